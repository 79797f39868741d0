// vitri::WindingNumber: the octree (each node's range split by octant around its box's centre, a counting
// sort) and the Barnes-Hut evaluation; WindingSides, its calibration on the samples.
#include "vitri/rbf/winding.hpp"

#include "vitri/core/box.hpp"
#include "vitri/core/error.hpp"

#include <algorithm>
#include <memory>
#include <string>
#include <cmath>

namespace vitri {

namespace {

constexpr std::uint32_t kLeafSize = 16;  ///< a node with at most this many samples is a leaf
constexpr int kMaxDepth = 24;            ///< deeper nodes stay leaves (coincident samples)
/// A node seen from farther than this many times its radius counts as one dipole. 2 as in Barill et al.
/// (their beta): the first-order error is then a few percent of the node's share, well inside what the
/// callers ask (which side of 1/2 the number lies, with a margin of 1/4).
constexpr double kFarFactor = 2.0;
constexpr double kFourPi = 4.0 * 3.14159265358979323846;

}  // namespace

WindingNumber::WindingNumber(const std::vector<Point3>& points, const std::vector<Point3>& normals,
                             const std::vector<double>& areas) {
  if (points.empty()) throw InvalidArgument("WindingNumber: no point");
  if (normals.size() != points.size() || areas.size() != points.size())
    throw InvalidArgument("WindingNumber: " + std::to_string(points.size()) + " points, " +
                          std::to_string(normals.size()) + " normals, " + std::to_string(areas.size()) +
                          " areas (one each)");
  Box3 box;
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (!is_finite(points[i])) throw InvalidPoint(i, "non-finite coordinate (NaN or infinity)");
    if (!is_finite(normals[i])) throw InvalidPoint(i, "non-finite normal");
    if (!(areas[i] > 0) || !std::isfinite(areas[i])) throw InvalidPoint(i, "area not positive and finite");
    box.extend(points[i]);
  }
  const double diagonal = box.diagonal();
  skip2_ = 1e-24 * diagonal * diagonal;
  points_ = points;
  areas_ = areas;
  weighted_.resize(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) weighted_[i] = normals[i] * areas[i];
  nodes_.reserve(2 * points.size() / kLeafSize + 8);
  nodes_.push_back(Node{});
  nodes_[0].count = static_cast<std::uint32_t>(points.size());
  build(0, 0);
}

// Fills node `node`'s sums over its range, then splits the range into the octants around the range's
// box centre (std::partition three times) and recurses into the non-empty ones.
void WindingNumber::build(std::uint32_t node, int depth) {
  const std::uint32_t first = nodes_[node].first, count = nodes_[node].count;
  double area = 0;
  Point3 centroid{0, 0, 0}, dipole{0, 0, 0};
  Box3 box;
  for (std::uint32_t i = first; i < first + count; ++i) {
    area += areas_[i];
    centroid = centroid + points_[i] * areas_[i];
    dipole = dipole + weighted_[i];
    box.extend(points_[i]);
  }
  centroid = centroid * (1.0 / area);
  double r2 = 0;
  for (std::uint32_t i = first; i < first + count; ++i) r2 = std::max(r2, squared_norm(points_[i] - centroid));
  nodes_[node].center = centroid;
  nodes_[node].dipole = dipole;
  nodes_[node].radius2 = r2;
  nodes_[node].child = 0;
  nodes_[node].children = 0;
  if (count <= kLeafSize || depth >= kMaxDepth || !(box.diagonal() > 0)) return;
  // A counting sort by octant moves the three per-sample arrays together (stable: the input order is
  // kept within an octant, so the tree does not depend on anything but the input).
  const Point3 mid = (box.lo + box.hi) * 0.5;
  std::vector<std::uint8_t> octant(count);
  std::uint32_t starts[9] = {0};
  for (std::uint32_t k = 0; k < count; ++k) {
    const Point3& q = points_[first + k];
    octant[k] = static_cast<std::uint8_t>((q.x >= mid.x ? 1 : 0) | (q.y >= mid.y ? 2 : 0) | (q.z >= mid.z ? 4 : 0));
    ++starts[octant[k] + 1];
  }
  for (int k = 0; k < 8; ++k) starts[k + 1] += starts[k];
  {
    std::uint32_t at[8];
    std::copy(starts, starts + 8, at);
    std::vector<Point3> p(count), w(count);
    std::vector<double> a(count);
    for (std::uint32_t k = 0; k < count; ++k) {
      const std::uint32_t to = at[octant[k]]++;
      p[to] = points_[first + k];
      w[to] = weighted_[first + k];
      a[to] = areas_[first + k];
    }
    std::copy(p.begin(), p.end(), points_.begin() + first);
    std::copy(w.begin(), w.end(), weighted_.begin() + first);
    std::copy(a.begin(), a.end(), areas_.begin() + first);
  }
  // Children: one node per non-empty octant, contiguous.
  const auto child = static_cast<std::uint32_t>(nodes_.size());
  std::uint32_t made = 0;
  for (int k = 0; k < 8; ++k) {
    const std::uint32_t n = starts[k + 1] - starts[k];
    if (n == 0) continue;
    Node c;
    c.first = first + starts[k];
    c.count = n;
    nodes_.push_back(c);
    ++made;
  }
  nodes_[node].child = child;
  nodes_[node].children = made;
  for (std::uint32_t k = 0; k < made; ++k) build(child + k, depth + 1);
}

double WindingNumber::operator()(const Point3& x) const {
  double w;
  evaluate_batch(&x, 1, &w);
  return w;
}

void WindingNumber::operator()(const Point3* x, std::size_t n, double* w) const {
  for (std::size_t b = 0; b < n; b += kBatch) {
    const std::size_t m = std::min(kBatch, n - b);
    evaluate_batch(x + b, m, w + b);
  }
}

// One traversal for up to kBatch points: a stack entry carries the points that opened its parent, and
// each point decides at each node exactly as operator() does. A point's nodes are popped in the order
// of its own traversal (the batch's depth-first order restricted to the nodes that point opens, a
// subtree-closed set, keeps their order), so each sum adds the same terms in the same order: a point's
// value does not depend on the others in its batch, bit for bit (operator() is a batch of one).
void WindingNumber::evaluate_batch(const Point3* x, std::size_t m, double* w) const {
  double sum[kBatch] = {0};
  if (nodes_.empty()) {
    std::fill(w, w + m, 0.0);
    return;
  }
  struct Entry {
    std::uint32_t node;
    std::uint32_t mask;  // bit k: point x[k] visits the node
  };
  Entry stack[8 * kMaxDepth + 8];
  int top = 0;
  stack[top++] = {0, (1u << m) - 1};
  const double far2 = kFarFactor * kFarFactor;
  while (top > 0) {
    const Entry e = stack[--top];
    const Node& nd = nodes_[e.node];
    std::uint32_t open = 0;
    for (std::size_t k = 0; k < m; ++k) {
      if (!(e.mask >> k & 1u)) continue;
      const Point3 d = nd.center - x[k];
      const double d2 = squared_norm(d);
      if (d2 > far2 * nd.radius2 && d2 > skip2_) sum[k] += dot(nd.dipole, d) / (d2 * std::sqrt(d2));
      else open |= 1u << k;
    }
    if (!open) continue;
    if (nd.children == 0) {
      // The leaf's samples summed exactly for the points that opened it: samples outer, points inner
      // (each sample read once; each point's terms still added in the samples' order).
      std::size_t near[kBatch], count = 0;
      for (std::size_t k = 0; k < m; ++k)
        if (open >> k & 1u) near[count++] = k;
      for (std::uint32_t i = nd.first; i < nd.first + nd.count; ++i) {
        const Point3 pi = points_[i], wi = weighted_[i];
        for (std::size_t c = 0; c < count; ++c) {
          const std::size_t k = near[c];
          const Point3 q = pi - x[k];
          const double q2 = squared_norm(q);
          if (q2 > skip2_) sum[k] += dot(wi, q) / (q2 * std::sqrt(q2));
        }
      }
      continue;
    }
    for (std::uint32_t k = 0; k < nd.children; ++k) stack[top++] = {nd.child + k, open};
  }
  for (std::size_t k = 0; k < m; ++k) w[k] = sum[k] / kFourPi;
}

WindingSides::WindingSides(const std::vector<Point3>& points, const std::vector<Point3>& normals,
                           const std::vector<double>& areas, double offset)
    : w_(points, normals, areas) {
  if (!(offset > 0) || !std::isfinite(offset)) throw InvalidArgument("WindingSides: offset must be > 0");
  const std::size_t step = std::max<std::size_t>(1, points.size() / 1000);
  std::vector<double> levels, jumps;
  for (std::size_t i = 0; i < points.size(); i += step) {
    const double inside = w_(points[i] - normals[i] * offset), outside = w_(points[i] + normals[i] * offset);
    levels.push_back(0.5 * (inside + outside));
    jumps.push_back(inside - outside);
  }
  auto median = [](std::vector<double>& v) {
    std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
    return v[v.size() / 2];
  };
  level_ = median(levels);
  jump_ = median(jumps);
}

int WindingSides::side_of(double w) const {
  if (w > level_ + 0.25 * jump_) return -1;
  if (w < level_ - 0.25 * jump_) return 1;
  return 0;
}

int WindingSides::operator()(const Point3& x) const {
  if (!(jump_ > 0.25)) return 0;
  return side_of(w_(x));
}

void WindingSides::operator()(const Point3* x, std::size_t n, int* side) const {
  if (!(jump_ > 0.25)) {
    std::fill(side, side + n, 0);
    return;
  }
  double w[WindingNumber::kBatch];
  for (std::size_t b = 0; b < n; b += WindingNumber::kBatch) {
    const std::size_t m = std::min(WindingNumber::kBatch, n - b);
    w_(x + b, m, w);
    for (std::size_t k = 0; k < m; ++k) side[b + k] = side_of(w[k]);
  }
}

WindingSides mesh_winding_sides(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F, double offset) {
  if (F.cols() != 3 || V.cols() != 3) throw InvalidArgument("mesh_winding_sides: V and F must have 3 columns");
  if (!(offset > 0) || !std::isfinite(offset)) throw InvalidArgument("WindingSides: offset must be > 0");
  for (Eigen::Index r = 0; r < V.rows(); ++r)
    if (!V.row(r).allFinite())
      throw InvalidPoint(static_cast<std::size_t>(r), "mesh_winding_sides: non-finite vertex position");
  struct Face {
    Point3 p0, e1, e2, normal;
    double area;
  };
  std::vector<Face> faces;
  faces.reserve(static_cast<std::size_t>(F.rows()));
  double total = 0;  // samples at the offset's size
  for (Eigen::Index t = 0; t < F.rows(); ++t) {
    Point3 p[3];
    for (int k = 0; k < 3; ++k) {
      const int v = F(t, k);
      if (v < 0 || v >= V.rows())
        throw InvalidArgument("mesh_winding_sides: triangle " + std::to_string(t) + " names vertex " +
                              std::to_string(v) + ", not a row of V (" + std::to_string(V.rows()) + " rows)");
      p[k] = {V(v, 0), V(v, 1), V(v, 2)};
    }
    const Point3 n = cross(p[1] - p[0], p[2] - p[0]);
    const double twice = norm(n);
    if (!(twice > 0)) continue;
    faces.push_back({p[0], p[1] - p[0], p[2] - p[0], n / twice, 0.5 * twice});
    total += std::max(1.0, 2.0 * faces.back().area / (offset * offset));
  }
  if (faces.empty()) throw InvalidArgument("mesh_winding_sides: no triangle of positive area");
  // A triangle is one dipole only when it is small beside the offset at which the calibration reads w
  // (a large one seen from its centroid at the offset reads far more than its solid angle): each is cut
  // into k x k similar triangles of side about the offset (k <= 64, at most about 4 x 10^6 samples).
  const double size = offset * std::max(1.0, std::sqrt(total / 4e6));
  std::vector<Point3> points, normals;
  std::vector<double> areas;
  for (const Face& f : faces) {
    const int k = static_cast<int>(std::min(64.0, std::ceil(std::sqrt(2.0 * f.area) / size)));
    const double a = f.area / (static_cast<double>(k) * k);
    auto at = [&](double u, double v) { return f.p0 + f.e1 * (u / k) + f.e2 * (v / k); };
    for (int i = 0; i < k; ++i)
      for (int j = 0; i + j < k; ++j) {
        points.push_back(at(i + 1.0 / 3, j + 1.0 / 3));  // the triangle (i, j) (i + 1, j) (i, j + 1)
        normals.push_back(f.normal);
        areas.push_back(a);
        if (i + j + 1 < k) {  // and (i + 1, j) (i + 1, j + 1) (i, j + 1)
          points.push_back(at(i + 2.0 / 3, j + 2.0 / 3));
          normals.push_back(f.normal);
          areas.push_back(a);
        }
      }
  }
  return WindingSides(points, normals, areas, offset);
}

bool settle_far_field_by_mesh(LocalRbfOptions& local, const Eigen::MatrixXd& V, const Eigen::MatrixXi& F,
                              double offset) {
  auto sides = std::make_shared<const WindingSides>(mesh_winding_sides(V, F, offset));
  if (!sides->encloses()) return false;
  local.far_side = [sides](const Point3& x) { return (*sides)(x); };
  local.far_sides = [sides](const Point3* x, std::size_t n, int* side) { (*sides)(x, n, side); };
  local.far_side_anchors = false;
  return true;
}

}  // namespace vitri
