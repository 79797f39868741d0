// prepare_scan(): scanned points to oriented points (docs/scans.md). The steps, each a named function:
//   distinct positions -> neighbourhoods (k from the data) -> outliers set aside -> neighbourhoods of the
//   inliers -> local quadric fits (noise, tangent planes) -> projection onto them -> orientation (given
//   normals checked, viewpoint or sensors checked, or estimated) -> a neighbour vote on the signs.
#include "vitri/rbf/scan.hpp"

#include "vitri/core/error.hpp"
#include "vitri/core/spatial_order.hpp"
#include "vitri/rbf/normals.hpp"
#include "vitri/rbf/point_index.hpp"
#include "vitri/rbf/winding.hpp"

#include "normals_detail.hpp"
#include "parallel.hpp"
#include "spaced_subset.hpp"

#include <Eigen/Dense>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numeric>
#include <sstream>

namespace vitri {
namespace {

using Id = PointIndex::Id;
constexpr std::size_t kGrain = 2048;
constexpr double kPi = 3.14159265358979323846;

/// k nearest neighbours of every point of an index (itself excluded), row-major n x k, and their distances.
struct Neighbours {
  std::size_t k = 0;
  std::vector<Id> ids;
  std::vector<double> dist;
  Id at(std::size_t i, std::size_t c) const { return ids[i * k + c]; }
  double d(std::size_t i, std::size_t c) const { return dist[i * k + c]; }
};

/// The `k` nearest points of `index` (p's points, themselves included) of every p[i] (or of those `only`
/// marks), handed to visit(i, ids, d2) on the threads. The points are visited along a Morton curve, each
/// chunk's queries bounded by the triangle inequality from the previous one (within = |q - r| + the k-th
/// distance of r): the same answers as nearest(), in about half the time for the 96 nearest of points
/// given in no spatial order (cache, and a search pruned from its start).
template <typename Visit>
void sweep_nearest(const std::vector<Point3>& p, const PointIndex& index, std::size_t k, unsigned threads,
                   const std::vector<std::uint8_t>* only, Visit&& visit) {
  const std::vector<std::size_t> order = detail::spatial_order(p);
  const std::size_t want = std::min(k, index.size());
  rbf_detail::parallel_chunks(order.size(), threads, kGrain, [&](std::size_t b, std::size_t e) {
    std::vector<Id> ids;
    std::vector<double> d2;
    bool have = false;  // r: the last point queried in this chunk, and its k-th distance
    Point3 r;
    double r_kth = 0;
    for (std::size_t o = b; o < e; ++o) {
      const std::size_t i = order[o];
      if (only && !(*only)[i]) continue;
      if (have) {
        // Widened by far more than the rounding of these few operations (relative 1e-16 each).
        const double within = (norm(p[i] - r) + r_kth) * (1.0 + 1e-9);
        index.nearest_within(p[i], k, within * within, ids, &d2);
      }
      if (!have || ids.size() < want) index.nearest(p[i], k, ids, &d2);  // (never, but never wrong)
      have = !d2.empty();
      r = p[i];
      r_kth = have ? std::sqrt(d2.back()) : 0.0;
      visit(i, ids, d2);
    }
  });
}

/// Row i of `nb` from the nb.k + 1 nearest of p[self] (`ids`, `d2`), p[self] left out (self: i unless
/// the rows are those of a subset).
void fill_row(std::size_t i, const std::vector<Id>& ids, const std::vector<double>& d2, Neighbours& nb,
              std::size_t self) {
  const std::size_t k = nb.k;
  std::size_t c = 0;
  for (std::size_t j = 0; j < ids.size() && c < k; ++j) {
    if (ids[j] == self) continue;
    nb.ids[i * k + c] = ids[j];
    nb.dist[i * k + c] = std::sqrt(d2[j]);
    ++c;
  }
  for (; c < k; ++c) {  // fewer points than k + 1 (never: callers check), repeat the last
    nb.ids[i * k + c] = nb.ids[i * k + c - 1];
    nb.dist[i * k + c] = nb.dist[i * k + c - 1];
  }
}

Neighbours nearest_neighbours(const std::vector<Point3>& p, const PointIndex& index, std::size_t k,
                              unsigned threads, const std::vector<std::uint8_t>* only = nullptr) {
  Neighbours nb;
  nb.k = k;
  nb.ids.resize(p.size() * k);
  nb.dist.resize(p.size() * k);
  sweep_nearest(p, index, k + 1, threads, only,
                [&](std::size_t i, const std::vector<Id>& ids, const std::vector<double>& d2) { fill_row(i, ids, d2, nb, i); });
  return nb;
}

/// The median (the upper one of an even count) of v, whose order it changes: for the per-point loops'
/// scratch vectors (no copy, no allocation).
double median_in_place(std::vector<double>& v) {
  if (v.empty()) return 0.0;
  const auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end());
  return *mid;
}

double median(std::vector<double> v) { return median_in_place(v); }

/// prepare_scan()'s test for wider neighbourhoods puts its question first to at most about this many
/// points (an even subsample of a larger scan), and answers from them when their share above the
/// threshold is more than kStructureBand standard errors (0.5 / sqrt(sample)) away from a half.
constexpr std::size_t kStructureSample = 16384;
constexpr double kStructureBand = 5.0;

/// fit_neighbourhood()'s row: the point's own.
constexpr std::size_t kNoRow = std::numeric_limits<std::size_t>::max();

/// The local fit of one neighbourhood: tangent frame, the quadric height field over it, residual scale.
struct LocalFit {
  Point3 normal;      ///< unit normal of the quadric at the point's projection (unoriented)
  Point3 projected;   ///< the point moved onto the quadric along the frame's normal
  double noise = 0;   ///< weighted RMS residual of the neighbourhood to the quadric
  double plane = 0;   ///< RMS residual to the least-squares plane (curvature included)
  /// The neighbourhood's second variance over its largest (PCA): about 1 for a disc of neighbours, near
  /// 0 for a line of them (a sparse scan's rings, a scan line), whose plane, hence normal, is arbitrary.
  double spread = 0;
  bool collinear = false;
};

/// Below this spread (LocalFit::spread) a neighbourhood is a line of points: its normal says nothing of
/// the surface (the neighbourhood is 7 times longer than wide or more).
constexpr double kLinearSpread = 0.02;

/// A viewpoint outside the data's box is accepted when the orientation it gives agrees with the data's own
/// on at least this share of the points (one view of a scene or object; a merged multi-view cloud reads
/// far lower). From kViewpointSampleMin points on, the share is first measured on a sample
/// (sampled_agreement) and taken when farther than kViewpointBand from the limit: the shipped views read
/// 0.99-1.00 on a sample and on all points alike.
constexpr double kViewpointAgree = 0.9;
constexpr double kViewpointBand = 0.05;
constexpr std::size_t kViewpointSampleMin = 40000;
constexpr double kViewpointSampleRadius = 2.25;
constexpr std::size_t kViewpointSampleNeighbours = 16;

/// Fits point i's neighbourhood (itself included): PCA plane, then the weighted quadric height field
/// z = a + b x + c y + d x^2 + e xy + f y^2 in the plane's frame (Wendland weights over the neighbourhood
/// radius); a plane when the quadric is ill-conditioned. `side`, when given (oriented normals), keeps only
/// the neighbours on the point's own side of the surface (n_j . n_i > 0.3): the two sheets of a thin part
/// face away from each other, and a neighbourhood that straddles them must not fit one surface between.
LocalFit fit_neighbourhood(const std::vector<Point3>& p, const Neighbours& nb, std::size_t i,
                           const std::vector<Point3>* side = nullptr, std::size_t nb_row = kNoRow,
                           std::size_t use = 0) {
  // (the rows of a subset: point i's neighbours in row nb_row; `use`: only the first `use` of the row)
  const std::size_t row = nb_row == kNoRow ? i : nb_row;
  const std::size_t count = use ? std::min(use, nb.k) : nb.k;
  LocalFit out;
  const Point3 o = p[i];
  // The neighbours used (relative positions and distances), the point itself first.
  thread_local std::vector<std::pair<Eigen::Vector3d, double>> near;
  near.clear();
  near.push_back({Eigen::Vector3d::Zero(), 0.0});
  for (std::size_t c = 0; c < count; ++c) {
    const Id j = nb.at(row, c);
    if (side && dot((*side)[j], (*side)[i]) < 0.3) continue;
    near.push_back({(p[j] - o).eigen(), nb.d(row, c)});
  }
  const std::size_t m = near.size();
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const auto& q : near) mean += q.first;
  mean /= static_cast<double>(m);
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  for (const auto& q : near) {
    const Eigen::Vector3d v = q.first - mean;
    cov += v * v.transpose();
  }
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(cov);
  const Eigen::Vector3d ev = solver.eigenvalues();
  out.collinear = m < 3 || !(ev(1) > 1e-6 * ev(2));
  out.spread = ev(2) > 0 ? std::max(0.0, ev(1)) / ev(2) : 0.0;
  out.plane = std::sqrt(std::max(0.0, ev(0)) / static_cast<double>(m));
  const Eigen::Vector3d nrm = solver.eigenvectors().col(0).normalized();
  const Eigen::Vector3d e1 = solver.eigenvectors().col(2).normalized();
  const Eigen::Vector3d e2 = nrm.cross(e1);
  out.normal = Point3::from(nrm);
  if (side && dot(out.normal, (*side)[i]) < 0) out.normal = -out.normal;
  out.projected = o;
  out.noise = out.plane;
  if (out.collinear) {
    if (side) out.normal = (*side)[i];
    return out;
  }
  // Quadric in the frame centred at the neighbourhood's mean.
  double reach = 0;
  for (const auto& q : near) reach = std::max(reach, q.second);
  const double radius = std::max(reach, 1e-300) * 1.1;
  Eigen::Matrix<double, 6, 6> ata = Eigen::Matrix<double, 6, 6>::Zero();
  Eigen::Matrix<double, 6, 1> atz = Eigen::Matrix<double, 6, 1>::Zero();
  double wsum = 0;
  auto design = [&](const Eigen::Vector3d& q, double& z) {
    const Eigen::Vector3d r = q - mean;
    const double x = r.dot(e1) / radius, y = r.dot(e2) / radius;
    z = r.dot(nrm);
    Eigen::Matrix<double, 6, 1> a;
    a << 1, x, y, x * x, x * y, y * y;
    return a;
  };
  auto weight = [&](double dist) {
    const double t = std::min(1.0, dist / radius);
    const double u = 1 - t;
    return u * u * u * u * (4 * t + 1) + 1e-3;
  };
  thread_local std::vector<std::pair<Eigen::Matrix<double, 6, 1>, std::pair<double, double>>> rows;
  rows.clear();
  for (const auto& q : near) {
    double z;
    const auto a = design(q.first, z);
    rows.push_back({a, {z, weight(q.second)}});
  }
  for (const auto& [a, zw] : rows) {
    ata += zw.second * a * a.transpose();
    atz += zw.second * zw.first * a;
    wsum += zw.second;
  }
  Eigen::Matrix<double, 6, 1> coef;
  const Eigen::LDLT<Eigen::Matrix<double, 6, 6>> ldlt(ata);
  bool quadric = m >= 10 && ldlt.info() == Eigen::Success && ldlt.isPositive();
  if (quadric) {
    coef = ldlt.solve(atz);
    const Eigen::Matrix<double, 6, 1> d = ldlt.vectorD();
    quadric = coef.allFinite() && d.minCoeff() > 1e-10 * d.maxCoeff();
  }
  if (!quadric) {  // the plane through the weighted mean
    coef.setZero();
    coef(0) = atz(0) / ata(0, 0);
  }
  double r2 = 0;
  for (const auto& [a, zw] : rows) {
    const double r = zw.first - a.dot(coef);
    r2 += zw.second * r * r;
  }
  out.noise = std::sqrt(r2 / wsum);
  // The point's own height over the quadric, and the quadric's normal there.
  const Eigen::Vector3d r0 = -mean;
  const double x = r0.dot(e1) / radius, y = r0.dot(e2) / radius;
  const double z = r0.dot(nrm);
  const double zq = coef(0) + coef(1) * x + coef(2) * y + coef(3) * x * x + coef(4) * x * y + coef(5) * y * y;
  const double dzdx = (coef(1) + 2 * coef(3) * x + coef(4) * y) / radius;
  const double dzdy = (coef(2) + coef(4) * x + 2 * coef(5) * y) / radius;
  const Eigen::Vector3d qn = (nrm - dzdx * e1 - dzdy * e2).normalized();
  if (qn.allFinite()) {
    out.normal = Point3::from(qn);
    if (side && dot(out.normal, (*side)[i]) < 0) out.normal = -out.normal;
  }
  double move = zq - z;
  // Never further than the neighbourhood's own scale: a bad fit does not throw a point away.
  const double cap = std::max(3 * out.noise, 3 * out.plane);
  move = std::max(-cap, std::min(cap, move));
  out.projected = o + Point3::from(move * nrm);
  return out;
}

/// Whether the wider neighbourhood (row `row` of `wide`, of point i) holds a second sheet parallel to the
/// point's own, on one side: at least 3 neighbours within the k-point neighbourhood's radius `r` of the
/// point's normal line (its k-point fit's), off its sheet by more than max(4 x that fit's residual, r / 2),
/// all on one side, their offsets spread by under a fifth of their mean (a parallel face: the other side
/// of a thin part, not vegetation over ground or clutter). The wider fit's residual there is not structure
/// between the scales (step 2) but that face.
bool second_sheet(const std::vector<Point3>& p, const Neighbours& wide, std::size_t row, std::size_t i,
                  const LocalFit& own, double r) {
  const double off = std::max(4 * own.noise, 0.5 * r);
  std::size_t count = 0, up = 0;
  double sum = 0, sum2 = 0;
  for (std::size_t c = 0; c < wide.k; ++c) {
    const Point3 v = p[wide.at(row, c)] - p[i];
    const double h = dot(v, own.normal);
    if (std::abs(h) > off && norm(v - h * own.normal) < r) {
      ++count;
      up += h > 0;
      sum += std::abs(h);
      sum2 += h * h;
    }
  }
  if (count < 3 || (up != 0 && up != count)) return false;
  const double mean = sum / static_cast<double>(count);
  const double var = std::max(0.0, sum2 / static_cast<double>(count) - mean * mean);
  return std::sqrt(var) < 0.2 * mean;
}

/// Directions averaged by dequantize_depth() (the office capture: Euler characteristic -425 without the
/// average, -239 with 32 of the point's own or a neighbouring level).
constexpr std::size_t kDequantizeSmooth = 32;

/// Depth quantization undone (ScanOptions::dequantize; docs/scans.md, step 1b). A depth camera stores
/// one measure of each point in discrete steps (the z offset from the viewpoint for structured light and
/// stereo, the range for some scanners): the cloud is a stack of levels, each a band of the surface seen
/// as flat, and the surface between bands a step. Interpolating them makes terraces. The true measure of
/// a point lies within half a step of its level's value; across the band of level j it runs from the
/// middle of levels j-1 and j (at the band's edge toward level j-1) to the middle of j and j+1 (at its
/// other edge). Each point takes the value interpolated between the two edges by its distances to them,
/// measured as angles seen from the viewpoint (the nearest point of level j-1 and of j+1 among the
/// points' directions: the image's distances, whatever the depth), and moves along its ray to it. An
/// edge farther than 20 of the image's typical spacings counts as that far, and a point with neither
/// edge nearer stays (a wide flat band). The values are then averaged over the kDequantizeSmooth nearest
/// directions of its own or a neighbouring level (ragged band edges: pixels dither between two levels;
/// not across an occluding edge), each kept within its own step.
/// Never more than half a step; nothing when the data show no quantization. Returns the points moved.
std::size_t dequantize_depth(std::vector<Point3>& p, const Point3& vp, unsigned threads, ScanReport& rep) {
  const std::size_t n = p.size();
  if (n < 1000) return 0;
  auto measure = [&](int m, const Point3& q) {
    const Point3 d = q - vp;
    return m == 0 ? d.x : m == 1 ? d.y : m == 2 ? d.z : norm(d);
  };
  // Distinct values of each measure; the quantized one has at most n / 100 and 10x fewer than the others.
  std::array<std::size_t, 4> distinct{};
  std::vector<double> v(n);
  for (int m = 0; m < 4; ++m) {
    for (std::size_t i = 0; i < n; ++i) v[i] = measure(m, p[i]);
    std::sort(v.begin(), v.end());
    distinct[m] = static_cast<std::size_t>(std::unique(v.begin(), v.end()) - v.begin());
  }
  int chosen = -1;
  for (int m = 0; m < 4; ++m) {
    bool coarse = distinct[m] >= 3 && distinct[m] * 100 <= n;
    for (int o = 0; o < 4 && coarse; ++o)
      if (o != m && distinct[m] * 10 > distinct[o]) coarse = false;
    if (coarse) chosen = m;
  }
  if (chosen < 0) return 0;
  std::vector<double> value(n);
  for (std::size_t i = 0; i < n; ++i) value[i] = measure(chosen, p[i]);
  // Every point on one side of the viewpoint along the measure (moving along the ray scales it).
  const bool positive = value[0] > 0;
  for (std::size_t i = 0; i < n; ++i)
    if (!(positive ? value[i] > 0 : value[i] < 0)) return 0;
  std::vector<double> level(value);
  std::sort(level.begin(), level.end());
  level.erase(std::unique(level.begin(), level.end()), level.end());
  const std::size_t L = level.size();
  std::vector<std::uint32_t> at(n);
  std::vector<std::vector<Id>> members(L);
  std::vector<Point3> dir(n);
  for (std::size_t i = 0; i < n; ++i) {
    at[i] = static_cast<std::uint32_t>(std::lower_bound(level.begin(), level.end(), value[i]) - level.begin());
    members[at[i]].push_back(static_cast<Id>(i));
    const Point3 d = p[i] - vp;
    const double r = norm(d);
    dir[i] = r > 0 ? d / r : d;
  }
  std::vector<PointIndex> index(L);
  {
    std::vector<Point3> at_level;
    for (std::size_t j = 0; j < L; ++j) {
      at_level.clear();
      for (Id i : members[j]) at_level.push_back(dir[i]);
      index[j].build(at_level, 1);  // ids: positions in members[j] (an index's arrays follow its ids)
    }
  }
  // The image's typical spacing: the median angle to the nearest point of the same level.
  std::vector<double> same(n, std::numeric_limits<double>::infinity());
  rbf_detail::parallel_chunks(n, threads, kGrain, [&](std::size_t b, std::size_t e) {
    std::vector<Id> ids;
    std::vector<double> d2;
    for (std::size_t i = b; i < e; ++i) {
      index[at[i]].nearest(dir[i], 2, ids, &d2);  // itself (or a point of the same direction) first
      if (ids.size() == 2) same[i] = std::sqrt(d2[1]);
    }
  });
  std::vector<double> finite;
  for (double a : same)
    if (std::isfinite(a)) finite.push_back(a);
  if (finite.empty()) return 0;
  const double reach = 20 * median(finite);
  if (!(reach > 0)) return 0;
  double smin = std::numeric_limits<double>::infinity(), smax = 0;
  for (std::size_t j = 1; j < L; ++j) {
    smin = std::min(smin, level[j] - level[j - 1]);
    smax = std::max(smax, level[j] - level[j - 1]);
  }
  // The measure interpolated across each band, and the interval its quantization allows.
  std::vector<double> target(value), lo(n), hi(n);
  rbf_detail::parallel_chunks(n, threads, kGrain, [&](std::size_t b, std::size_t e) {
    std::vector<Id> ids;
    std::vector<double> d2;
    for (std::size_t i = b; i < e; ++i) {
      const std::size_t j = at[i];
      const double step_below = j > 0 ? level[j] - level[j - 1] : level[j + 1] - level[j];
      const double step_above = j + 1 < L ? level[j + 1] - level[j] : step_below;
      lo[i] = level[j] - step_below / 2, hi[i] = level[j] + step_above / 2;
      auto edge = [&](std::size_t other) {  // the angle to the nearest point of level `other`, capped
        if (other >= L) return reach;
        index[other].nearest(dir[i], 1, ids, &d2);
        return ids.empty() ? reach : std::min(reach, std::sqrt(d2[0]));
      };
      const double below = j > 0 ? edge(j - 1) : reach, above = edge(j + 1);
      if (below >= reach && above >= reach) continue;
      target[i] = lo[i] + below / (below + above) * (hi[i] - lo[i]);
    }
  });
  // Smoothed over the image: the band edges of a noisy capture are ragged (pixels dither between two
  // levels), and so is the distance to them; each point takes the mean of the values of its
  // kDequantizeSmooth nearest directions of its own or a neighbouring level, kept within its own interval.
  {
    const PointIndex all(dir, threads);
    std::vector<double> mean(n);
    rbf_detail::parallel_chunks(n, threads, kGrain, [&](std::size_t b, std::size_t e) {
      std::vector<Id> ids;
      for (std::size_t i = b; i < e; ++i) {
        all.nearest(dir[i], kDequantizeSmooth, ids);
        double sum = 0;
        std::size_t used = 0;
        for (const Id q : ids)  // the same surface: its own level or a neighbouring one (not across an
          if (at[q] + 1 >= at[i] && at[q] <= at[i] + 1) sum += target[q], ++used;  // occluding edge)
        mean[i] = used == 0 ? target[i] : std::clamp(sum / static_cast<double>(used), lo[i], hi[i]);
      }
    });
    target.swap(mean);
  }
  std::size_t moved = 0;
  for (std::size_t i = 0; i < n; ++i)
    if (target[i] != value[i]) p[i] = vp + (p[i] - vp) * (target[i] / value[i]), ++moved;
  rep.quantized = chosen == 0 ? "x" : chosen == 1 ? "y" : chosen == 2 ? "z" : "range";
  rep.levels = L;
  rep.step_min = smin;
  rep.step_max = smax;
  return moved;
}

/// The side of the area per point around point i (its k-th neighbour's distance x sqrt(pi / k)).
double local_spacing(const Neighbours& nb, std::size_t i) {
  return nb.d(i, nb.k - 1) * std::sqrt(kPi / static_cast<double>(nb.k));
}

/// The neighbour lists and fits after points were removed: `p` and `index` hold the survivors, `keep` their
/// old ids (increasing), `nb` and `fit` the old lists and fits (rewritten in place for the survivors). A
/// survivor none of whose k nearest was removed keeps them, renumbered: removing points brings none
/// nearer, and the renumbering keeps the ids' order, so ties (broken by id) fall the same way; its fit,
/// a function of its own and its neighbours' positions in list order, is the same. The others are queried
/// again in `index` and fitted again. The result equals nearest_neighbours() and fit_neighbourhood() over
/// the survivors, at the cost of the points near a removed one.
std::vector<std::uint8_t> refresh_after_removal(const std::vector<Point3>& p, const PointIndex& index,
                                                const std::vector<std::size_t>& keep, Neighbours& nb,
                                                std::vector<LocalFit>& fit, unsigned threads) {
  const std::size_t k = nb.k, old_n = fit.size(), n = keep.size();
  constexpr Id kGone = std::numeric_limits<Id>::max();
  std::vector<Id> renumber(old_n, kGone);
  for (std::size_t r = 0; r < n; ++r) renumber[keep[r]] = static_cast<Id>(r);
  std::vector<std::uint8_t> stale(n, 0);
  for (std::size_t r = 0; r < n; ++r) {  // in place: row r reads row keep[r] >= r
    const std::size_t u = keep[r];
    for (std::size_t c = 0; c < k; ++c) {
      const Id j = renumber[nb.ids[u * k + c]];
      stale[r] |= j == kGone;
      nb.ids[r * k + c] = j;
      nb.dist[r * k + c] = nb.dist[u * k + c];
    }
    fit[r] = fit[u];
  }
  nb.ids.resize(n * k);
  nb.dist.resize(n * k);
  fit.resize(n);
  sweep_nearest(p, index, k + 1, threads, &stale,
                [&](std::size_t i, const std::vector<Id>& ids, const std::vector<double>& d2) { fill_row(i, ids, d2, nb, i); });
  std::vector<std::size_t> again;
  for (std::size_t r = 0; r < n; ++r)
    if (stale[r]) again.push_back(r);
  // The fits after every list is complete (a fit reads only its own list, but keep the phases apart).
  rbf_detail::parallel_chunks(again.size(), threads, kGrain, [&](std::size_t b, std::size_t e) {
    for (std::size_t a = b; a < e; ++a) fit[again[a]] = fit_neighbourhood(p, nb, again[a]);
  });
  return stale;
}

/// Connected components of the neighbour graph restricted to edges no longer than 3 local spacings (of
/// the longer-spaced end), among the points not flagged in `skip` (null: all): the root of each point's
/// component (the smallest id in it).
std::vector<Id> surface_components(const Neighbours& nb, std::size_t n, const std::vector<std::uint8_t>* skip) {
  std::vector<Id> parent(n);
  std::iota(parent.begin(), parent.end(), Id(0));
  auto find = [&](Id a) {
    while (parent[a] != a) a = parent[a] = parent[parent[a]];
    return a;
  };
  for (std::size_t i = 0; i < n; ++i) {
    if (skip && (*skip)[i]) continue;
    for (std::size_t c = 0; c < nb.k; ++c) {
      const Id j = nb.at(i, c);
      if (skip && (*skip)[j]) continue;
      if (nb.d(i, c) > 3.0 * std::max(local_spacing(nb, i), local_spacing(nb, j))) continue;
      const Id a = find(static_cast<Id>(i)), b = find(j);
      if (a != b) parent[std::max(a, b)] = std::min(a, b);
    }
  }
  for (std::size_t i = 0; i < n; ++i) parent[i] = find(static_cast<Id>(i));
  return parent;
}

/// Neighbours of the dimension estimate of the volume rule (find_outliers).
constexpr std::size_t kDimensionNeighbours = 64;

/// The local dimension of the points around each point `only` marks, from the distances d_1 <= ... <= d_K
/// to its K = kDimensionNeighbours nearest (Levina & Bickel's maximum-likelihood estimate,
/// 1 / mean_j log(d_K / d_j)): about 2 on a surface, 3 for points scattered in a volume, higher still for a
/// point above a denser surface (its neighbours all nearly as far). 0 where not computed.
std::vector<double> local_dimension(const std::vector<Point3>& p, const PointIndex& index,
                                    const std::vector<std::uint8_t>& only, unsigned threads) {
  std::vector<double> dim(p.size(), 0.0);
  if (p.size() <= kDimensionNeighbours + 1) return dim;
  sweep_nearest(p, index, kDimensionNeighbours + 1, threads, &only,
                [&](std::size_t i, const std::vector<Id>& ids, const std::vector<double>& d2) {
                  (void)ids;  // d2[0] is the point itself
                  const double last = d2.back();
                  double s = 0;
                  std::size_t m = 0;
                  for (std::size_t c = 1; c + 1 < d2.size(); ++c) {
                    if (!(d2[c] > 0)) continue;
                    s += 0.5 * std::log(last / d2[c]);
                    ++m;
                  }
                  dim[i] = s > 0 ? static_cast<double>(m) / s : 0.0;
                });
  return dim;
}

/// A point against the quadric of its neighbours (itself left out): its height over the quadric and the
/// neighbours' own residuals' scale (the larger of 1.4826 x their median absolute residual and the RMS of
/// all but their largest).
struct QuadricCheck {
  double residual = 0;  ///< |height of the point over the neighbours' quadric|
  double scale = 0;     ///< scale of the neighbours' residuals (see above)
  bool valid = false;   ///< false when the quadric is ill-conditioned (no verdict)
};

/// The neighbours of point i (row i of nb, the point excluded) fitted by the least-squares quadric height
/// field over their PCA frame (`mean`: their centroid relative to p[i]; `frame`: the eigenvectors of their
/// covariance, smallest first), unweighted: a point off the surface the others agree on, where the plane
/// test would see curvature (find_outliers).
QuadricCheck neighbours_quadric(const std::vector<Point3>& p, const Neighbours& nb, std::size_t i,
                                const Eigen::Vector3d& mean, const Eigen::Matrix3d& frame) {
  QuadricCheck out;
  const std::size_t k = nb.k;
  if (k < 10) return out;
  const Eigen::Vector3d nrm = frame.col(0), e1 = frame.col(2), e2 = frame.col(1);
  const double radius = std::max(nb.d(i, k - 1), 1e-300);
  // Only where the point lies among its neighbours, not beside them (a rim, a sparse point beside a
  // denser region): a quadric extrapolated to the point has no verdict.
  if (std::hypot(mean.dot(e1), mean.dot(e2)) > 0.3 * radius) return out;
  Eigen::Matrix<double, 6, 6> ata = Eigen::Matrix<double, 6, 6>::Zero();
  Eigen::Matrix<double, 6, 1> atz = Eigen::Matrix<double, 6, 1>::Zero();
  auto design = [&](const Eigen::Vector3d& r, double& z) {
    const double x = r.dot(e1) / radius, y = r.dot(e2) / radius;
    z = r.dot(nrm);
    Eigen::Matrix<double, 6, 1> a;
    a << 1, x, y, x * x, x * y, y * y;
    return a;
  };
  thread_local std::vector<std::pair<Eigen::Matrix<double, 6, 1>, double>> rows;
  rows.clear();
  for (std::size_t c = 0; c < k; ++c) {
    double z;
    const auto a = design((p[nb.at(i, c)] - p[i]).eigen() - mean, z);
    rows.push_back({a, z});
    ata += a * a.transpose();
    atz += z * a;
  }
  const Eigen::LDLT<Eigen::Matrix<double, 6, 6>> ldlt(ata);
  if (ldlt.info() != Eigen::Success || !ldlt.isPositive()) return out;
  const Eigen::Matrix<double, 6, 1> d = ldlt.vectorD();
  if (!(d.minCoeff() > 1e-10 * d.maxCoeff())) return out;
  const Eigen::Matrix<double, 6, 1> coef = ldlt.solve(atz);
  if (!coef.allFinite()) return out;
  thread_local std::vector<double> res;
  res.clear();
  for (const auto& [a, z] : rows) res.push_back(std::abs(z - a.dot(coef)));
  // The larger of the robust scale and the RMS of all but the largest residual: where the quadric does
  // not follow the surface (a finger, an ear's rim, a crease) most neighbours still fit it and the point
  // does not; the misfit then shows in the RMS. Around a stray point the neighbours fit their surface
  // and both are small; the largest left out, another stray point among the neighbours does not hide
  // this one. (All of them: 12 of 120 stray points of the test kept; the largest eighth: 3x the points
  // of noisy curved parts set aside.)
  std::sort(res.begin(), res.end());
  const std::size_t kept = k - 1;
  double r2 = 0;
  for (std::size_t c = 0; c < kept; ++c) r2 += res[c] * res[c];
  out.scale = std::max(1.4826 * res[k / 2], std::sqrt(r2 / static_cast<double>(kept)));
  double z0;
  const auto a0 = design(-mean, z0);
  out.residual = std::abs(z0 - a0.dot(coef));
  out.valid = true;
  return out;
}

/// What find_outliers() hands from one round of prepare_scan()'s outlier rules to the next.
struct OutlierRound {
  /// The volume candidates of the round (one flag per point; the caller keeps the rows of the points
  /// kept, in their new order, before the next round).
  std::vector<std::uint8_t> volume;
  double typical_reach = 0;  ///< the round's median reach (k-th neighbour distance)
};

/// Outliers among distinct points: far off the plane of their neighbours, much sparser than their
/// neighbours, scattered in a volume, or in a small cluster cut off from the rest. Returns a flag per point.
/// `stale` (a later round: the rows refresh_after_removal() recomputed; null: every point) with `last`
/// (that round's OutlierRound, rows of the kept points): a point whose row, whose neighbours' rows and
/// whose side of the density thresholds did not change gets the per-point verdict of the round before
/// (kept, its volume flag) without computing it again: every input of that verdict is the same. `last`
/// is then overwritten with this round's.
std::vector<std::uint8_t> find_outliers(const std::vector<Point3>& p, const PointIndex& index, const Neighbours& nb,
                                        const std::vector<double>& noise, unsigned threads, OutlierRound& last,
                                        const std::vector<std::uint8_t>* stale) {
  const std::size_t n = p.size(), k = nb.k;
  std::vector<double> mean_d(n);
  for (std::size_t i = 0; i < n; ++i) {
    double s = 0;
    for (std::size_t c = 0; c < k; ++c) s += nb.d(i, c);
    mean_d[i] = s / static_cast<double>(k);
  }
  std::vector<std::uint8_t> out(n, 0);
  std::vector<double> reach(n);
  for (std::size_t i = 0; i < n; ++i) reach[i] = nb.d(i, k - 1);
  const double typical_reach = median(reach);
  std::vector<std::uint8_t> volume(n, 0);
  // The points whose verdict must be computed: all, or those whose inputs changed (their row or a
  // neighbour's row: mean distances, reaches, noise; or the k-th neighbour between the two rounds'
  // thresholds of 2 x the typical reach).
  std::vector<std::uint8_t> compute(n, 1);
  if (stale && last.volume.size() == n) {
    const double lo = 2.0 * std::min(typical_reach, last.typical_reach);
    const double hi = 2.0 * std::max(typical_reach, last.typical_reach);
    for (std::size_t i = 0; i < n; ++i) {
      bool changed = (*stale)[i] || (nb.d(i, k - 1) >= lo && nb.d(i, k - 1) <= hi);
      for (std::size_t c = 0; c < k && !changed; ++c) changed = (*stale)[nb.at(i, c)];
      compute[i] = changed;
    }
  }
  rbf_detail::parallel_chunks(n, threads, kGrain, [&](std::size_t b, std::size_t e) {
    std::vector<double> tmp;
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver;
    for (std::size_t i = b; i < e; ++i) {
      if (!compute[i]) {  // kept by the round before (a point it set aside is gone), the same inputs
        volume[i] = last.volume[i];
        continue;
      }
      tmp.clear();
      for (std::size_t c = 0; c < k; ++c) tmp.push_back(mean_d[nb.at(i, c)]);
      const double local_d = median_in_place(tmp);
      // Density: a point whose neighbours are 3x farther than theirs are (flying pixels, stray returns).
      if (mean_d[i] > 3.0 * local_d) {
        out[i] = 1;
        continue;
      }
      // Plane of the neighbours without the point.
      Eigen::Vector3d mean = Eigen::Vector3d::Zero();
      for (std::size_t c = 0; c < k; ++c) mean += (p[nb.at(i, c)] - p[i]).eigen();
      mean /= static_cast<double>(k);
      Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
      for (std::size_t c = 0; c < k; ++c) {
        const Eigen::Vector3d v = (p[nb.at(i, c)] - p[i]).eigen() - mean;
        cov += v * v.transpose();
      }
      solver.compute(cov);
      const Eigen::Vector3d nrm = solver.eigenvectors().col(0);
      const double off = std::abs(mean.dot(nrm));
      // Scattered in a volume rather than on a surface (the neighbours' spread is nearly isotropic: the
      // smallest of the three variances is over 8% of their sum, where a noisy surface gives a few
      // percent) and sparser than the data at large (the k-th neighbour 2x farther than is typical):
      // outliers spread over the box, whose neighbours are other outliers, so that the rules relative to
      // the neighbours see nothing wrong. A candidate only: a sparse thin part (an ear, a blade sampled
      // 10x more sparsely than the rest) also gives a thick neighbourhood; the dimension decides below
      // (the rule on the distance to the plane still applies to a candidate).
      const Eigen::Vector3d ev = solver.eigenvalues();
      volume[i] = ev(0) > 0.08 * ev.sum() && nb.d(i, k - 1) > 2.0 * typical_reach;
      tmp.clear();
      for (std::size_t c = 0; c < k; ++c) tmp.push_back(noise[nb.at(i, c)]);
      const double local_noise = median_in_place(tmp);
      // Spacing of the neighbourhood (side of the area per point, the neighbours' own: a point off the
      // surface sees its neighbours from afar) as the floor: clean data lose nothing.
      tmp.clear();
      for (std::size_t c = 0; c < k; ++c) tmp.push_back(reach[nb.at(i, c)]);
      const double h = median_in_place(tmp) * std::sqrt(kPi / static_cast<double>(k));
      if (off > std::max(4.0 * local_noise, 2.0 * h)) {
        out[i] = 1;
        continue;
      }
      // Off the quadric of its neighbours (curvature followed, so the floor can be half the plane
      // rule's) by more than 6 x their own residuals' scale (QuadricCheck): a stray point within a few
      // spacings of the surface, which the plane rule's floor of 2 h lets through (h is about twice the
      // nearest-neighbour spacing of a random sample) and whose own neighbourhoods it makes look noisy.
      // Asked where the data are about as dense as is typical (the k-th neighbour at most 2x as far, as
      // in the volume rule): a sparse thin part's points (an ear sampled 10x more sparsely) are few and
      // far apart, and one of them set aside opens a hole (bunny-density10: Euler characteristic 2 -> -2).
      if (nb.d(i, k - 1) > 2.0 * typical_reach) continue;
      const QuadricCheck qc = neighbours_quadric(p, nb, i, mean, solver.eigenvectors());
      if (qc.valid && qc.residual > std::max(6.0 * qc.scale, h)) out[i] = 1;
    }
  });
  last.volume = volume;
  last.typical_reach = typical_reach;
  // The volume candidates: set aside unless the points around them lie on a surface. The local dimension
  // (64 neighbours: past the thickness of a thin part, whose two sides then read as one sheet) of the
  // candidate and its k neighbours, their median: on the simulated cases (docs/scans.md) sparse thin
  // parts give 1.6-2.4 (medians 2.0-2.4), outliers in the box 2.2-10 (medians 3-7); a line of flying
  // pixels gives about 1. Kept when within (1.5, 2.5).
  std::vector<std::uint8_t> around(n, 0);
  bool any = false;
  for (std::size_t i = 0; i < n; ++i)
    if (volume[i]) {
      any = true;
      around[i] = 1;
      for (std::size_t c = 0; c < k; ++c) around[nb.at(i, c)] = 1;
    }
  if (any) {
    const std::vector<double> dim = local_dimension(p, index, around, threads);
    std::vector<double> tmp;
    std::vector<std::uint8_t> sheet(n, 0);
    for (std::size_t i = 0; i < n; ++i) {
      if (!volume[i]) continue;
      tmp.assign(1, dim[i]);
      for (std::size_t c = 0; c < k; ++c) tmp.push_back(dim[nb.at(i, c)]);
      const double d = median_in_place(tmp);
      sheet[i] = d > 1.5 && d < 2.5;
    }
    for (std::size_t i = 0; i < n; ++i)
      if (volume[i] && !sheet[i]) out[i] = 1;
    // A sheet among outliers: the estimate reads about 2 for one outlier in 5 of those spread over the
    // box, which then lie among set-aside points. A kept candidate with more than 40% of its k
    // neighbours set aside is set aside too, until nothing changes; a sparse thin part keeps most of its
    // points and stays. (A third instead: the outlier cases the same, a thick plate of the tests loses
    // 45% more of its points; a half: a blob on turbine-outliers5. The mesher's component rule weighs
    // what stays against the set-aside points: ScanPoints::set_aside.)
    for (bool more = true; more;) {
      more = false;
      for (std::size_t i = 0; i < n; ++i) {
        if (!volume[i] || out[i]) continue;
        std::size_t aside = 0;
        for (std::size_t c = 0; c < k; ++c) aside += out[nb.at(i, c)];
        if (5 * aside > 2 * k) out[i] = 1, more = true;
      }
    }
  }
  // Small clusters: components of the neighbour graph (edges no longer than 3 local spacings) among the
  // points kept so far, fewer than max(2k, n / 1000) points (at most n / 4: a small input is not all outliers).
  const std::vector<Id> root = surface_components(nb, n, &out);
  std::vector<std::size_t> size(n, 0);
  for (std::size_t i = 0; i < n; ++i)
    if (!out[i]) ++size[root[i]];
  const std::size_t min_size = std::min(std::max<std::size_t>(2 * k, n / 1000), n / 4);
  for (std::size_t i = 0; i < n; ++i)
    if (!out[i] && size[root[i]] < min_size) out[i] = 1;
  return out;
}

/// Fraction of neighbour pairs along the surface whose normals point to opposite sides.
double disagreement(const std::vector<Point3>& p, const Neighbours& nb, const std::vector<Point3>& n,
                    const std::vector<LocalFit>& fit, unsigned threads) {
  const std::size_t chunks = (p.size() + kGrain - 1) / kGrain;
  std::vector<std::size_t> along(chunks, 0), opposite(chunks, 0);  // per chunk of kGrain points
  rbf_detail::parallel_chunks(chunks, threads, 1, [&](std::size_t cb, std::size_t ce) {
    for (std::size_t chunk = cb; chunk < ce; ++chunk)
      for (std::size_t i = chunk * kGrain; i < std::min(p.size(), (chunk + 1) * kGrain); ++i) {
        if (fit[i].spread < kLinearSpread) continue;  // a line of neighbours: its normal is arbitrary
        for (std::size_t c = 0; c < nb.k; ++c) {
          const Id j = nb.at(i, c);
          if (fit[j].spread < kLinearSpread) continue;
          const Point3 e = p[j] - p[i];
          const double half = 0.5 * norm(e);
          if (std::abs(dot(n[i], e)) > half || std::abs(dot(n[j], e)) > half) continue;
          ++along[chunk];
          opposite[chunk] += dot(n[i], n[j]) < 0;
        }
      }
  });
  const std::size_t a = std::accumulate(along.begin(), along.end(), std::size_t(0));
  const std::size_t o = std::accumulate(opposite.begin(), opposite.end(), std::size_t(0));
  return a ? static_cast<double>(o) / static_cast<double>(a) : 0.0;
}

/// One vote: a point whose sign disagrees with a clear majority (weighted by |n_i . n_j|, pairs along the
/// surface) of its neighbours takes theirs. `strong` = the majority needed, as a fraction of the weight.
/// Points flagged in `undecided` always take the majority. Returns the flips.
std::size_t vote_signs(const std::vector<Point3>& p, const Neighbours& nb, std::vector<Point3>& n,
                       const std::vector<std::uint8_t>* undecided, double strong, unsigned threads) {
  // Each point reads the signs before the vote (n) and writes its own in `flip`: the threads share
  // nothing they write.
  std::vector<std::uint8_t> flip(p.size(), 0);
  rbf_detail::parallel_chunks(p.size(), threads, kGrain, [&](std::size_t b, std::size_t e) {
    for (std::size_t i = b; i < e; ++i) {
      double agree = 0, against = 0;
      for (std::size_t c = 0; c < nb.k; ++c) {
        const Id j = nb.at(i, c);
        if (undecided && (*undecided)[j]) continue;
        const Point3 d = p[j] - p[i];
        const double half = 0.5 * norm(d);
        if (std::abs(dot(n[i], d)) > half || std::abs(dot(n[j], d)) > half) continue;
        const double w = dot(n[i], n[j]);
        (w >= 0 ? agree : against) += std::abs(w);
      }
      const double total = agree + against;
      const bool must = undecided && (*undecided)[i];
      flip[i] = total > 0 && (against > strong * total || (must && against > agree));
    }
  });
  std::size_t flips = 0;
  for (std::size_t i = 0; i < p.size(); ++i)
    if (flip[i]) n[i] = -n[i], ++flips;
  return flips;
}

/// Whether a part whose normals lie mostly along `axis` is layered along it: a thin closed object (a
/// disc, a plate, a turbine's wheel) has points on both faces over most of its extent, a 2.5D sheet
/// (airborne data, a facade, a table top seen from one side) one layer at each place, except at walls,
/// edges and trees. Up to 2000 of the part's points whose normals are within 37 degrees of the axis are
/// examined: layered when another point of the part lies within 2 local spacings of its line along the
/// axis but more than 4 local spacings away along it, or more than 1.5 away with its normal opposite
/// (the tree oriented the faces apart; two layers of one sign so close may be a misregistered overlap).
/// More than half layered: a closed thin object.
bool layered_along(const std::vector<Point3>& p, const std::vector<Point3>& n, const Neighbours& nb,
                   const std::vector<Id>& members, const Point3& axis) {
  const Eigen::Vector3d a = axis.eigen().normalized();
  Eigen::Vector3d e1 = a.unitOrthogonal(), e2 = a.cross(e1);
  std::vector<Point3> flat(members.size());
  for (std::size_t m = 0; m < members.size(); ++m) {
    const Eigen::Vector3d q = p[members[m]].eigen();
    flat[m] = Point3{q.dot(e1), q.dot(e2), 0.0};
  }
  std::vector<std::size_t> along;
  for (std::size_t m = 0; m < members.size(); ++m)
    if (std::abs(dot(n[members[m]], axis)) >= 0.8) along.push_back(m);
  if (along.size() < 32) return false;
  const PointIndex index(flat, 1);
  const std::size_t stride = std::max<std::size_t>(1, along.size() / 2000);
  std::size_t examined = 0, layered = 0;
  std::vector<Id> ball;
  for (std::size_t s = 0; s < along.size(); s += stride) {
    const std::size_t m = along[s];
    const Id i = members[m];
    const double h = local_spacing(nb, i);
    if (!(h > 0)) continue;
    ++examined;
    index.ball(flat[m], 4 * h * h, ball);
    const double height = dot(p[i], axis);
    for (const Id o : ball)
      if (const double gap = std::abs(dot(p[members[o]], axis) - height);
          gap > 4 * h || (gap > 1.5 * h && dot(n[members[o]], n[i]) < -0.5)) {
        ++layered;
        break;
      }
  }
  return examined > 0 && 2 * layered > examined;
}

/// A contiguous run of ids (a group of IdGroups).
struct IdSpan {
  const Id* first = nullptr;
  const Id* last = nullptr;
  const Id* begin() const { return first; }
  const Id* end() const { return last; }
  std::size_t size() const { return static_cast<std::size_t>(last - first); }
};

/// The ids 0 .. n - 1 grouped by a key in [0, n) (a union-find's roots), in compressed rows: group g is
/// ids_[start_[g], start_[g + 1]), in increasing id. 8 bytes a point, where a vector per group took 48.
class IdGroups {
 public:
  explicit IdGroups(const std::vector<Id>& key) : start_(key.size() + 1, 0), ids_(key.size()) {
    for (const Id k : key) ++start_[k + 1];
    std::partial_sum(start_.begin(), start_.end(), start_.begin());
    std::vector<std::uint32_t> fill(start_.begin(), start_.end() - 1);
    for (std::size_t i = 0; i < key.size(); ++i) ids_[fill[key[i]]++] = static_cast<Id>(i);
  }
  IdSpan operator[](std::size_t g) const { return {ids_.data() + start_[g], ids_.data() + start_[g + 1]}; }

 private:
  std::vector<std::uint32_t> start_;
  std::vector<Id> ids_;
};

/// repair_regions(): neighbours whose oriented normals lie within 45 degrees of each other share a region
/// (points whose kRegionNear nearest all do);
/// a region takes part when it holds kRegionShare of its component's points and kRegionMinPoints, the
/// largest kRegionMax of them; the winding number is read at kRegionSamples points of each, half a
/// spacing off on both sides.
constexpr double kRegionDot = 0.7;
constexpr double kRegionShare = 0.01;
constexpr std::size_t kRegionMinPoints = 64;
constexpr std::size_t kRegionMax = 16;
constexpr std::size_t kRegionSamples = 128;
constexpr std::size_t kRegionNear = 8;
constexpr double kRegionLevelRms = 0.15;

/// Smooth points: those whose tangent plane is clear, that is whose neighbourhood's quadric fits within
/// max(kSmoothResidual x the scan's noise, kSmoothSpacing x the local spacing) (`residual`: LocalFit::noise
/// of each point, `noise`: their median) and whose kRegionNear nearest all have normals within 45 degrees
/// of theirs. A sharp edge's points are not: their neighbourhoods straddle the faces (residual), and the
/// tangent planes there turn from one face's to the other's along the shorter arc, in steps the angle test
/// alone passes (a cone's rim, 117 degrees between the faces' normals, reads as a 63-degree bend: its
/// base and side chained into one region in 2 of 4 samples).
constexpr double kSmoothResidual = 3.0;
constexpr double kSmoothSpacing = 0.02;

/// The residual a smooth point's fit stays within (smooth_points' first test).
double residual_bound(const Neighbours& nb, std::size_t i, double noise) {
  return std::max(kSmoothResidual * noise, kSmoothSpacing * local_spacing(nb, i));
}

std::vector<std::uint8_t> smooth_points(const Neighbours& nb, const std::vector<double>& residual, double noise,
                                        const std::vector<Point3>& n) {
  const std::size_t count = n.size();
  std::vector<std::uint8_t> smooth(count, 0);
  for (std::size_t i = 0; i < count; ++i) {
    bool ok = residual[i] <= residual_bound(nb, i, noise);
    for (std::size_t c = 0; c < std::min(nb.k, kRegionNear) && ok; ++c) ok = dot(n[i], n[nb.at(i, c)]) >= kRegionDot;
    smooth[i] = ok;
  }
  return smooth;
}

/// Regions: the root of each point's region (the least index in it), where neighbouring smooth points
/// of one part (`comp`) whose oriented normals agree within 45 degrees, no farther apart than 3 local
/// spacings, share a region; a point that is not smooth is a region of its own.
std::vector<Id> smooth_regions(const Neighbours& nb, const std::vector<Id>& comp,
                               const std::vector<std::uint8_t>& smooth, const std::vector<Point3>& n) {
  const std::size_t count = n.size();
  std::vector<double> h(count);
  for (std::size_t i = 0; i < count; ++i) h[i] = local_spacing(nb, i);
  std::vector<Id> parent(count);
  std::iota(parent.begin(), parent.end(), Id(0));
  auto find = [&](Id a) {
    while (parent[a] != a) a = parent[a] = parent[parent[a]];
    return a;
  };
  for (std::size_t i = 0; i < count; ++i)
    for (std::size_t c = 0; c < nb.k && smooth[i]; ++c) {
      const Id j = nb.at(i, c);
      if (!smooth[j] || comp[j] != comp[i] || dot(n[i], n[j]) < kRegionDot) continue;
      if (nb.d(i, c) > 3.0 * std::max(h[i], h[j])) continue;
      const Id a = find(static_cast<Id>(i)), b = find(j);
      if (a != b) parent[std::max(a, b)] = std::min(a, b);
    }
  for (std::size_t i = 0; i < count; ++i) parent[i] = find(static_cast<Id>(i));
  return parent;
}

/// Gives the `waiting` points their signs from the decided ones (state != 0) outward, layer by layer, and
/// marks them decided (state 2): each takes the sign its decided neighbours favour, weighted by
/// (n_i . n_j)^4, and in each layer only the points with a decided neighbour whose tangent plane is nearly
/// theirs (|n_i . n_j| >= kRegionDot) decide, while some have one. Across a sharp edge the signs' relation
/// is unreliable: a cone's base point, flipped, agrees with the side's normals (+0.45 each at a rim of 63
/// degrees) about as much as its right sign agrees with its base neighbours; weighted by |n_i . n_j| and
/// decided in plain layers, 115 points within 5 spacings of a clean cone's rim (40,000 points, its base
/// flipped by the tree and repaired) kept the wrong sign: lips below the base, 4 handles in its mesh.
/// Returns the points whose sign changed.
std::size_t propagate_signs(const Neighbours& nb, std::vector<Id> waiting, std::vector<std::uint8_t>& state,
                            std::vector<Point3>& n) {
  std::size_t changed = 0;
  std::vector<Id> layer, still;
  std::vector<std::uint8_t> flip_to, strong;
  while (!waiting.empty()) {
    layer.clear(), flip_to.clear(), still.clear(), strong.clear();
    bool any_strong = false;
    for (const Id i : waiting) {
      double agree = 0, against = 0, best = 0;
      for (std::size_t k = 0; k < nb.k; ++k) {
        const Id j = nb.at(i, k);
        if (!state[j]) continue;
        const double w = dot(n[i], n[j]), w2 = w * w;
        (w >= 0 ? agree : against) += w2 * w2;
        best = std::max(best, std::abs(w));
      }
      if (agree + against > 0) {
        layer.push_back(i), flip_to.push_back(against > agree), strong.push_back(best >= kRegionDot);
        any_strong = any_strong || best >= kRegionDot;
      } else {
        still.push_back(i);
      }
    }
    if (any_strong) {  // the weak ones wait for a later layer
      std::size_t kept = 0;
      for (std::size_t a = 0; a < layer.size(); ++a) {
        if (strong[a]) layer[kept] = layer[a], flip_to[kept] = flip_to[a], ++kept;
        else still.push_back(layer[a]);
      }
      layer.resize(kept), flip_to.resize(kept);
    }
    if (layer.empty()) break;  // cut off from every decided point
    for (std::size_t a = 0; a < layer.size(); ++a) {
      if (flip_to[a]) n[layer[a]] = -n[layer[a]], ++changed;
      state[layer[a]] = 2;
    }
    waiting.swap(still);
  }
  return changed;
}

/// Gives each point that is not smooth by its residual (smooth_points' first test) the oriented normal of
/// the decided neighbour whose tangent plane passes nearest it, when nearer than both the residual bound
/// and half the point's own residual (the plane fits it clearly better than its own fit): the smooth
/// points are decided, and the others take their normals from them outward, layer by layer. On a
/// sharp edge the neighbourhood straddles the faces: the fitted plane lies between theirs and its sign
/// disagrees with one face whichever it is, while the point's own face's plane passes through it (and the
/// band is wider than a neighbourhood: the layers carry each face's plane up to the edge). A point that no
/// decided plane passes near keeps its normal. Only points near an edge wait: two of their neighbours'
/// tangent planes more than 25 degrees apart (not a thin part's two sheets, nor the two layers of a
/// misregistered overlap: parallel). prepare_scan() runs it only on clean data (the scan's noise at most
/// kEdgeCleanNoise of its spacing, at most 0.1% of the points moved by the layers' merging: a model's
/// samples, a CAD part): on real scans (noise of 0.13 to 0.74 spacings) the planes of clutter and noise
/// pass near as often, and the meshes of five of the seven shipped scans came out with more handles or
/// holes (Euler characteristic 5-30 lower); on the misregistered noise_topology inputs, handles came on
/// three models of five. Returns the points whose normal changed.
constexpr double kEdgeCleanNoise = 0.05;
constexpr double kEdgeTurnCos = 0.906;  // 25 degrees

std::size_t edge_normals_from_faces(const std::vector<Point3>& p, const Neighbours& nb,
                                    const std::vector<double>& residual, double noise, std::vector<Point3>& n,
                                    unsigned threads) {
  std::vector<std::uint8_t> state = smooth_points(nb, residual, noise, n);  // 1: decided
  std::vector<double> bound(p.size());
  std::vector<Id> waiting;
  for (std::size_t i = 0; i < p.size(); ++i) {
    bound[i] = residual_bound(nb, i, noise);
    if (state[i] || !(residual[i] > bound[i])) continue;
    // An edge: two of the neighbours' tangent planes more than kEdgeTurn apart (the faces'); parallel
    // ones (the two layers of a misregistered overlap, a thin part's sheets) are no edge.
    bool turns = false;
    for (std::size_t a = 0; a < nb.k && !turns; ++a)
      for (std::size_t c = a + 1; c < nb.k && !turns; ++c)
        turns = std::abs(dot(n[nb.at(i, a)], n[nb.at(i, c)])) < kEdgeTurnCos;
    if (turns) waiting.push_back(static_cast<Id>(i));
  }
  constexpr Id kNone = std::numeric_limits<Id>::max();
  std::vector<Id> pick;
  std::vector<Id> still;
  std::size_t count = 0;
  while (!waiting.empty()) {
    pick.assign(waiting.size(), kNone);
    rbf_detail::parallel_chunks(waiting.size(), threads, kGrain, [&](std::size_t b, std::size_t e) {
      for (std::size_t a = b; a < e; ++a) {
        const Id i = waiting[a];
        double best = std::min(bound[i], 0.5 * residual[i]);
        for (std::size_t c = 0; c < nb.k; ++c) {
          const Id j = nb.at(i, c);
          if (!state[j]) continue;
          const double off = std::abs(dot(n[j], p[i] - p[j]));
          if (off < best) best = off, pick[a] = j;
        }
      }
    });
    still.clear();
    std::size_t decided = 0;
    for (std::size_t a = 0; a < waiting.size(); ++a) {
      if (pick[a] == kNone) {  // no decided plane near yet: its own face's may come in a later layer
        still.push_back(waiting[a]);
        continue;
      }
      n[waiting[a]] = n[pick[a]];  // (the picks were all made before: this layer reads none of these)
      state[waiting[a]] = 1;
      ++decided;
    }
    count += decided;
    if (decided == 0) break;  // the rest keep their normals
    waiting.swap(still);
  }
  return count;
}

/// Repairs, within each connected component of the neighbour graph that does not look closed (its
/// normals, area-weighted, do not sum to about 0), the signs of whole regions that the spanning tree set
/// across a sharp edge: a cone's base meets its side at 63 degrees, the normals there are 117 degrees
/// apart, and Hoppe's tree, which keeps the sign along an edge whose normals agree, flips the base whole.
/// A region is a part of the component whose smooth points (smooth_points, from each point's fit
/// `residual` and the scan's `noise`) have neighbouring normals within 45 degrees (no sharp edge inside).
/// Each region's normals give it a winding number (WindingNumber of its points), and the level of the
/// whole (the mean of w just inside and just outside a point) is 1/2 on every point of a consistently
/// oriented closed surface: a region flipped wrongly lowers or raises the level at the points of the
/// others (not at its own: its own jump follows its normals). The regions' signs are chosen greedily to
/// bring the levels nearest 1/2 (least squares over the samples); the points between the regions then
/// take their signs from them (propagate_signs), and the result is kept only when the component, as it
/// then is, looks closed (normals summing to under 0.3 of its area, mean level within 0.1 of 1/2, the
/// levels within kRegionLevelRms of 1/2 in RMS) and the error fell to a quarter: an open scan (one view,
/// a scene) is left to settle_components. Returns the points whose sign changed.
std::size_t repair_regions(const std::vector<Point3>& p, const Neighbours& nb, const std::vector<Id>& comp,
                           const std::vector<double>& residual, double noise, std::vector<Point3>& n,
                           unsigned threads) {
  const std::size_t count = p.size();
  std::vector<double> area(count), h(count);
  for (std::size_t i = 0; i < count; ++i) h[i] = local_spacing(nb, i), area[i] = h[i] * h[i];
  // The parts that look closed (most scans of objects) need nothing: the regions are built only when
  // one part's normals do not sum to about 0.
  std::vector<Point3> comp_sum(count);
  std::vector<double> comp_area(count, 0.0);
  for (std::size_t i = 0; i < count; ++i) comp_sum[comp[i]] = comp_sum[comp[i]] + n[i] * area[i], comp_area[comp[i]] += area[i];
  auto looks_closed = [&](std::size_t c) { return norm(comp_sum[c]) < 0.3 * comp_area[c]; };
  bool any = false;
  for (std::size_t i = 0; i < count && !any; ++i) any = comp[i] == i && !looks_closed(i);
  if (!any) return 0;
  const std::vector<Id> parent = smooth_regions(nb, comp, smooth_points(nb, residual, noise, n), n);
  const IdGroups region_members(parent), comp_members(comp);
  // Scratch over all points, cleared after each part: 1 in a region taking part, 2 decided after.
  std::vector<std::uint8_t> state(count, 0);
  std::size_t changed = 0;
  for (std::size_t c = 0; c < count; ++c) {
    const IdSpan members = comp_members[c];
    if (members.size() < 2 * kRegionMinPoints || looks_closed(c)) continue;
    const double total_area = comp_area[c];
    // Its regions, largest first; those large enough take part.
    std::vector<Id> roots;
    for (const Id i : members)
      if (parent[i] == i) roots.push_back(i);
    std::sort(roots.begin(), roots.end(), [&](Id a, Id b) {
      return region_members[a].size() != region_members[b].size() ? region_members[a].size() > region_members[b].size() : a < b;
    });
    const std::size_t least =
        std::max(kRegionMinPoints, static_cast<std::size_t>(kRegionShare * static_cast<double>(members.size())));
    std::size_t m = 0;
    while (m < roots.size() && m < kRegionMax && region_members[roots[m]].size() >= least) ++m;
    if (m < 2) continue;
    for (std::size_t r = 0; r < m; ++r)
      for (const Id i : region_members[roots[r]]) state[i] = 1;
    // The samples and their two reads, half the component's median spacing off.
    std::vector<double> hs;
    for (const Id i : members) hs.push_back(h[i]);
    const double d = 0.5 * median(hs);
    std::vector<Point3> reads;  // sample k: reads 2k (outside) and 2k + 1 (inside)
    for (std::size_t r = 0; r < m; ++r) {
      const IdSpan rm = region_members[roots[r]];
      const std::size_t step = std::max<std::size_t>(1, rm.size() / kRegionSamples);
      for (std::size_t a = 0; a < rm.size(); a += step) {
        const Id i = rm.first[a];
        reads.push_back(p[i] + d * n[i]);
        reads.push_back(p[i] - d * n[i]);
      }
    }
    const std::size_t samples = reads.size() / 2;
    // Each region's level at every sample (its normals as they are), and the rest's.
    auto levels_of = [&](const std::vector<Id>& ids) {
      std::vector<Point3> rp, rn;
      std::vector<double> ra;
      for (const Id i : ids) rp.push_back(p[i]), rn.push_back(n[i]), ra.push_back(area[i]);
      const WindingNumber w(rp, rn, ra);
      std::vector<double> at(reads.size()), level(samples);
      rbf_detail::parallel_chunks(reads.size(), threads, 256, [&](std::size_t b, std::size_t e) {
        w(reads.data() + b, e - b, at.data() + b);
      });
      for (std::size_t k = 0; k < samples; ++k) level[k] = 0.5 * (at[2 * k] + at[2 * k + 1]);
      return level;
    };
    std::vector<std::vector<double>> g(m);
    for (std::size_t r = 0; r < m; ++r) {
      const IdSpan rm = region_members[roots[r]];
      g[r] = levels_of(std::vector<Id>(rm.begin(), rm.end()));
    }
    std::vector<double> rest(samples, 0.0);
    {
      std::vector<Id> others;
      for (const Id i : members)
        if (!state[i]) others.push_back(i);
      if (!others.empty()) rest = levels_of(others);
    }
    std::vector<int> sign(m, 1);
    auto error = [&](const std::vector<int>& s, double* mean_level) {
      double e = 0, sum = 0;
      for (std::size_t k = 0; k < samples; ++k) {
        double level = rest[k];
        for (std::size_t r = 0; r < m; ++r) level += s[r] * g[r][k];
        e += (level - 0.5) * (level - 0.5);
        sum += level;
      }
      if (mean_level) *mean_level = sum / static_cast<double>(samples);
      return e;
    };
    const double before = error(sign, nullptr);
    double now = before;
    for (std::size_t round = 0; round < m; ++round) {
      std::size_t best = m;
      double best_error = now;
      for (std::size_t r = 0; r < m; ++r) {
        sign[r] = -sign[r];
        const double e = error(sign, nullptr);
        sign[r] = -sign[r];
        if (e < best_error) best_error = e, best = r;
      }
      if (best == m) break;
      sign[best] = -sign[best];
      now = best_error;
    }
    if (!(now < 0.25 * before)) {
      for (const Id i : members) state[i] = 0;
      continue;
    }
    // The regions' signs applied, the points between them (the sharp edges, small parts) take their
    // signs again from the regions outward (propagate_signs), and the whole is judged as it then is (the
    // points between, 12% of a cone of 5,000 points, with the tree's signs put its mean level at 0.39).
    std::vector<Point3> saved;
    saved.reserve(members.size());
    for (const Id i : members) saved.push_back(n[i]);
    std::size_t flipped = 0;
    for (std::size_t r = 0; r < m; ++r)
      if (sign[r] < 0)
        for (const Id i : region_members[roots[r]]) n[i] = -n[i], ++flipped;
    std::vector<Id> waiting;
    for (const Id i : members)
      if (!state[i]) waiting.push_back(i);
    flipped += propagate_signs(nb, std::move(waiting), state, n);
    const std::vector<double> level = levels_of(std::vector<Id>(members.begin(), members.end()));
    double e = 0, mean_level = 0;
    for (const double l : level) e += (l - 0.5) * (l - 0.5), mean_level += l;
    mean_level /= static_cast<double>(samples);
    Point3 sum_after;
    for (const Id i : members) sum_after = sum_after + area[i] * n[i];
    // A closed surface consistently oriented: the level near 1/2 at (almost) every sample, not only on
    // average (an airborne scan's walls flipped make its mean level 0.36 and its normals sum to 0.33 of
    // its area, but the levels stray by 0.27 in RMS; the cone's by 0.05).
    const double rms = std::sqrt(e / static_cast<double>(samples));
    if (!(e < 0.25 * before) || !(rms < kRegionLevelRms) || std::abs(mean_level - 0.5) > 0.1 ||
        !(norm(sum_after) < 0.3 * total_area)) {
      std::size_t a = 0;
      for (const Id i : members) n[i] = saved[a++];
    } else {
      changed += flipped;
    }
    for (const Id i : members) state[i] = 0;
  }
  return changed;
}

/// settle_components(): a closed part with an unclear divergence sum is settled by its winding number
/// when it has at least this many points.
constexpr std::size_t kSettleWindingMin = 32;

/// Settles the sign of each connected component of the neighbour graph (edges no longer than 3 local
/// spacings) that the spanning tree oriented on its own: a closed component's outward normals satisfy
/// sum n . (p - c) > 0 (the divergence theorem: 3 x its volume), so a component whose normals give a clear
/// negative sum is flipped whole (an unclear sum on a closed one: its winding number's level decides); an open one (no clear sign) is made to agree with a common direction:
/// the mean normal of the largest open component, itself turned toward +z (up) when nothing else says.
/// Returns the points whose sign changed.
std::size_t settle_components(const std::vector<Point3>& p, const Neighbours& nb, const std::vector<Id>& root,
                              std::vector<Point3>& n, unsigned threads) {
  const std::size_t count = p.size();
  auto find = [&](Id a) { return root[a]; };
  // The sums over a part are weighted by each point's area (its local spacing squared): the integral of
  // n dA over a closed surface vanishes, the sum of unit normals of a closed surface sampled 10x more
  // densely on one side does not (cactus with one half thinned 10x: |sum| 0.35 per point, settled as
  // open and turned the wrong way; 0% oriented).
  std::vector<double> point_area(count);
  for (std::size_t i = 0; i < count; ++i) point_area[i] = local_spacing(nb, i) * local_spacing(nb, i);
  struct Part {
    std::size_t size = 0;
    double area = 0;
    Point3 centroid, normal_sum;  // area-weighted
    Eigen::Matrix3d tensor = Eigen::Matrix3d::Zero();  // sum of n n^T: where the normals point, unsigned
    double signed_sum = 0, abs_sum = 0;
    int verdict = 0;  // +1 closed outward, -1 closed inward, 0 open, 2 a sheet seen along `axis`
    bool unclear_closed = false;  // closed, but the divergence sum's sign is unclear
    Point3 axis;
  };
  std::vector<Part> part(count);
  for (std::size_t i = 0; i < count; ++i) {
    Part& q = part[find(static_cast<Id>(i))];
    ++q.size;
    q.area += point_area[i];
    q.centroid = q.centroid + p[i] * point_area[i];
    q.tensor += n[i].eigen() * n[i].eigen().transpose();
  }
  for (Part& q : part)
    if (q.area > 0) q.centroid = q.centroid * (1.0 / q.area);
  for (std::size_t i = 0; i < count; ++i) {
    Part& q = part[find(static_cast<Id>(i))];
    const double v = point_area[i] * dot(n[i], p[i] - q.centroid);
    q.signed_sum += v;
    q.abs_sum += std::abs(v);
    q.normal_sum = q.normal_sum + n[i] * point_area[i];
  }
  // Parts with most normals along one axis (its eigenvector of the normal tensor; zero elsewhere), and
  // whether they are layered along it (a thin closed object, not a sheet: layered_along()).
  std::vector<std::vector<Id>> flat_members(count);
  std::vector<Point3> flat_axis(count);
  for (std::size_t r = 0; r < count; ++r) {
    if (!part[r].size) continue;
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(part[r].tensor / static_cast<double>(part[r].size));
    if (es.eigenvalues()(2) >= 0.6) flat_axis[r] = Point3::from(es.eigenvectors().col(2).normalized());
  }
  for (std::size_t i = 0; i < count; ++i) {
    const Id r = find(static_cast<Id>(i));
    if (!(flat_axis[r] == Point3{})) flat_members[r].push_back(static_cast<Id>(i));
  }
  std::vector<std::uint8_t> thin_closed(count, 0);
  for (std::size_t r = 0; r < count; ++r)
    if (!flat_members[r].empty()) thin_closed[r] = layered_along(p, n, nb, flat_members[r], flat_axis[r]);
  for (std::size_t r = 0; r < count; ++r) {
    Part& q = part[r];
    if (!q.size) continue;
    // A sheet: most normals along one axis (airborne scans, facades, a table top). The tree cannot be
    // trusted across its sharp edges (roof to ground through a wall); it is seen from one side instead:
    // from above when the axis is within 45 degrees of z, else from the side most normals face. Unless
    // it is layered along that axis: a thin closed object (a disc) is settled as closed, below.
    if (!(flat_axis[r] == Point3{}) && !thin_closed[r]) {
      const Point3 axis = flat_axis[r];
      const bool vertical = std::abs(axis.z) >= std::sqrt(0.5);
      const double sign = vertical ? axis.z : dot(q.normal_sum, axis);
      q.axis = sign < 0 ? -axis : axis;
      q.verdict = 2;
      continue;
    }
    // Closed: the normals of a closed surface sum to about 0 (the integral of n dA vanishes), and the
    // divergence sum n . (p - c) has a clear sign (3 x the enclosed volume).
    const double ratio = q.abs_sum > 0 ? q.signed_sum / q.abs_sum : 0.0;
    const bool closed = norm(q.normal_sum) < 0.3 * q.area;
    q.verdict = !closed ? 0 : ratio > 0.5 ? 1 : ratio < -0.5 ? -1 : 0;
    q.unclear_closed = closed && q.verdict == 0;
  }
  // A closed part whose divergence sum is unclear: a thin part far from its centroid (a ring, a knot:
  // n . (p - c) is about R cos v + r on a torus, so the sum, 3 x the volume, is small beside its
  // magnitude). Its winding number's calibration tells instead (WindingSides: w read just inside and
  // just outside its points, half a spacing off): the level is about +1/2 when the normals point out,
  // -1/2 when they point in, against a jump of about 1.
  std::vector<std::vector<Id>> members(count);
  for (std::size_t i = 0; i < count; ++i) {
    const Id r = find(static_cast<Id>(i));
    if (part[r].unclear_closed) members[r].push_back(static_cast<Id>(i));
  }
  for (std::size_t r = 0; r < count; ++r) {
    if (members[r].size() < kSettleWindingMin) continue;
    std::vector<Point3> mp, mn;
    std::vector<double> area, h;
    for (const Id i : members[r]) {
      const double s = local_spacing(nb, i);
      if (s > 0) mp.push_back(p[i]), mn.push_back(n[i]), area.push_back(s * s), h.push_back(s);
    }
    if (mp.size() < kSettleWindingMin) continue;
    const WindingSides sides(mp, mn, area, 0.5 * median(h));
    if (sides.jump() > 0 && std::abs(sides.level()) > 0.25 * sides.jump())
      part[r].verdict = sides.level() > 0 ? 1 : -1;
  }
  std::size_t changed = 0;
  std::vector<std::uint8_t> undecided(count, 0);
  bool sheets = false;
  for (std::size_t i = 0; i < count; ++i) {
    const Part& q = part[find(static_cast<Id>(i))];
    bool flip = false;
    if (q.verdict == 2) {
      // Normals across the axis (a wall of a scene seen from above) keep the tree's sign, which is
      // consistent along the wall, until the vote: the sign of their small component along the axis is
      // the noise's (a terrestrial scan's building front came out in patches of both signs, foam).
      const double c = dot(n[i], q.axis);
      if (std::abs(c) < 0.2) undecided[i] = 1, sheets = true;
      else flip = c < 0;
    } else if (q.verdict != 0) {
      flip = q.verdict < 0;
    } else {
      flip = dot(q.normal_sum, Point3{0, 0, 1}) < 0;  // open, not a sheet: up when nothing else says
    }
    if (flip) n[i] = -n[i], ++changed;
  }
  if (sheets)
    for (int pass = 0; pass < 3; ++pass)
      if (vote_signs(p, nb, n, pass == 0 ? &undecided : nullptr, 0.8, threads) == 0) break;
  return changed;
}

/// Neighbours examined per point by merge_layers().
constexpr std::size_t kMergeNeighbours = 96;
/// The widest neighbourhood the noise can ask for (ScanOptions::k = 0).
constexpr std::size_t kMaxNeighbours = 96;
/// The projection widens a noisy region's neighbourhoods only where the wider fit's residual is at most
/// this many times the k-point fit's: noise, not shape (chosen on the samples of
/// bench/scans/noise_topology.py; docs/scans.md, step 7).
constexpr double kWideningGrowth = 2.5;

/// The neighbours a neighbourhood needs to see a surface through noise `rho` times its k-th neighbour's
/// distance (step 2: above 0.06 the neighbourhood widens, its radius growing as sqrt(k)), not rounded.
double neighbours_wanted(double rho) { return 16.0 * (rho / 0.06) * (rho / 0.06); }

/// Misregistered layers: the overlap of two views registered a little apart gives two sheets of the
/// same surface, with normals of the same sign, a few spacings apart; the offsets of one (+-D along
/// its normal) then contradict the other's, and the interpolant folds between them (handles, blobs).
/// Two sheets of one orientation so close are never both right: the space between them would be
/// outside for one and inside for the other (unless a sheet of the opposite orientation lies between,
/// a thin part). For each point, the points in a cylinder around its normal line (radius 2 h, half-height
/// 4 h, h its local spacing, at least 0.7 x the scan's median), of its orientation (normals within 60
/// degrees) and nearer than half the nearest opposite point along the line: when their heights along
/// the line (its own, 0, included) split into two clusters of at least a quarter of them each, by a
/// gap wider than h / 2 and than twice either cluster's spread (two layers, not one noisy or curved
/// sheet) and, where the region's noise (`noise`, per point) is below a quarter of that gap, each
/// cluster centred on the line (below), the point moves along its normal by the mean height (to the
/// layers' middle, weighted by their densities). Returns the number of points moved; `shift` receives each move (0 elsewhere) and
/// `reach` the distance to each examined point's farthest examined neighbour. With `only`, the points
/// it does not mark are not examined (their shift 0, their reach left as it was). `nb` gives the local
/// spacings; when it also holds the current neighbours of `p` (`nb_current`) and at least the 95 nearest
/// others, its rows are the 96 nearest (the point itself first, skipped) with no query. `layers`, when
/// given (sized p.size()), is set to 1 for every point moved where its region's noise is below a quarter
/// of the gap (two layers, as opposed to a move within noise), and left as it was elsewhere.
std::size_t merge_layers(const std::vector<Point3>& p, const std::vector<Point3>& n, const std::vector<double>& noise,
                         const PointIndex& index, const Neighbours& nb, bool nb_current, unsigned threads,
                         std::vector<double>& shift, std::vector<double>& reach,
                         const std::vector<std::uint8_t>* only = nullptr, std::vector<std::uint8_t>* layers = nullptr) {
  shift.assign(p.size(), 0.0);
  reach.resize(p.size(), 0.0);
  // The overlap of two layers is denser than either: its local spacing is up to half a layer's, so the
  // cylinder's scale has a floor of 0.7 x the scan's median local spacing.
  std::vector<double> spacing(p.size());
  for (std::size_t i = 0; i < p.size(); ++i) spacing[i] = local_spacing(nb, i);
  const double floor = 0.7 * median(spacing);
  const bool rows = nb_current && nb.k >= kMergeNeighbours - 1 && p.size() >= kMergeNeighbours;
  // Point i given `near`, its examined neighbours (itself may be among them, skipped). `same` and `keep`
  // are scratch: (height along n_i, lateral coordinates) of the cylinder's points of i's orientation.
  const auto examine = [&](std::size_t i, const std::vector<Id>& near, std::vector<Point3>& same,
                           std::vector<Point3>& keep) {
    const double h = std::max(spacing[i], floor);
    const double rc = 2.0 * h, half = 4.0 * h;
    const Eigen::Vector3d axis = n[i].eigen();
    const Eigen::Vector3d e1 = axis.unitOrthogonal(), e2 = axis.cross(e1);
    same.clear();
    double opposite = 2 * half;  // |t| of the nearest opposite point along the line (none: 2 half)
    for (const Id j : near) {
      if (j == i) continue;
      const Point3 v = p[j] - p[i];
      const double t = dot(v, n[i]);
      if (dot(v, v) - t * t > rc * rc || std::abs(t) > half) continue;
      const double c = dot(n[j], n[i]);
      if (c < -0.5) opposite = std::min(opposite, std::abs(t));
      else if (c > 0.5) same.push_back(Point3{t, v.eigen().dot(e1), v.eigen().dot(e2)});
    }
    // Two layers: the heights, sorted (the point's own, 0, included), split by their widest gap into
    // two clusters of at least a quarter of them each, the gap wider than half a spacing and than
    // twice either cluster's spread (one noisy or curved sheet spreads its heights without such a gap).
    // Where the region's noise is far below the gap (under a quarter of it), the clusters are structure,
    // not noise, and are two layers only if each is spread around the line (its points' lateral centroid
    // within rc / 2 of it): the layers of a misregistered overlap both cover the cylinder, where on one
    // clean sheet the points of a sparse sample that bend away at a crease, or a step of the surface (a
    // window's recess behind a wall), lie to one side (the elephant's smooth skin, 250,000 clean samples:
    // 231 points moved by up to 2.7 spacings without this condition, 6 with it). Where the noise is
    // comparable to the gap, the move is a local smoothing like the projection's, and stays.
    keep.assign(1, Point3{0.0, 0.0, 0.0});
    for (const Point3& q : same)
      if (std::abs(q.x) < 0.5 * opposite) keep.push_back(q);
    const std::size_t m = keep.size();
    if (m < 8) return;
    std::sort(keep.begin(), keep.end(), [](const Point3& a, const Point3& b) {
      return a.x != b.x ? a.x < b.x : a.y != b.y ? a.y < b.y : a.z < b.z;
    });
    const std::size_t lo_min = std::max<std::size_t>(3, m / 4);
    std::size_t cut = 0;
    double gap = 0;
    for (std::size_t c = lo_min; c + lo_min <= m; ++c)
      if (keep[c].x - keep[c - 1].x > gap) gap = keep[c].x - keep[c - 1].x, cut = c;
    if (cut == 0 || !(gap > 0.5 * h)) return;
    auto spread = [&](std::size_t from, std::size_t to) {
      double mean = 0, var = 0;
      for (std::size_t c = from; c < to; ++c) mean += keep[c].x;
      mean /= static_cast<double>(to - from);
      for (std::size_t c = from; c < to; ++c) var += (keep[c].x - mean) * (keep[c].x - mean);
      return std::sqrt(var / static_cast<double>(to - from));
    };
    if (!(gap > 2 * std::max(spread(0, cut), spread(cut, m)))) return;
    auto off_centre = [&](std::size_t from, std::size_t to) {
      double x = 0, y = 0;
      for (std::size_t c = from; c < to; ++c) x += keep[c].y, y += keep[c].z;
      const double count = static_cast<double>(to - from);
      return std::hypot(x / count, y / count);
    };
    if (noise[i] < 0.25 * gap && (off_centre(0, cut) > 0.5 * rc || off_centre(cut, m) > 0.5 * rc)) return;
    double sum = 0;
    for (const Point3& q : keep) sum += q.x;
    shift[i] = sum / static_cast<double>(m);
    if (layers) (*layers)[i] = noise[i] < 0.25 * gap;
  };
  // The cylinder's points among the nearest 96 (a ball would hold thousands where a sparse point borders
  // a dense region: room scans): about 3.9 h in an overlap of two layers, 5.5 h on one.
  if (rows) {  // the same ids in the same order as the query's (but itself), the same farthest
    rbf_detail::parallel_chunks(p.size(), threads, kGrain, [&](std::size_t b, std::size_t e) {
      std::vector<Id> near;
      std::vector<Point3> same, keep;
      for (std::size_t i = b; i < e; ++i) {
        if (only && !(*only)[i]) continue;
        near.assign(nb.ids.begin() + static_cast<std::ptrdiff_t>(i * nb.k),
                    nb.ids.begin() + static_cast<std::ptrdiff_t>(i * nb.k + kMergeNeighbours - 1));
        reach[i] = nb.d(i, kMergeNeighbours - 2);
        examine(i, near, same, keep);
      }
    });
  } else {
    // Every point of the cylinder lies within sqrt(rc^2 + half^2) = sqrt(20) h of the point. When that
    // ball (widened far beyond the rounding of the cylinder's test) holds at most kMergeNeighbours points,
    // the point itself included, they are all among its kMergeNeighbours nearest, so the ball's points
    // give the same cylinder as the nearest would: a ball query (about 63 points on one layer, 126 in an
    // overlap of two) instead of a selection of the 96 nearest. The reach is then the ball's radius (no
    // point farther out can change what the point examines). Fuller balls (a sparse point beside a dense
    // region, overlaps) take the 96 nearest as before.
    const std::vector<std::size_t> order = detail::spatial_order(p);
    rbf_detail::parallel_chunks(order.size(), threads, kGrain, [&](std::size_t b, std::size_t e) {
      std::vector<Id> near;
      std::vector<double> d2;
      std::vector<Point3> same, keep;
      for (std::size_t o = b; o < e; ++o) {
        const std::size_t i = order[o];
        if (only && !(*only)[i]) continue;
        const double h = std::max(spacing[i], floor);
        const double r = std::sqrt(20.0) * h * (1.0 + 1e-9);
        if (index.ball_up_to(p[i], r * r, kMergeNeighbours, near)) {
          reach[i] = r;
        } else {
          index.nearest(p[i], kMergeNeighbours, near, &d2);
          reach[i] = d2.empty() ? 0.0 : std::sqrt(d2.back());
        }
        examine(i, near, same, keep);
      }
    });
  }
  std::size_t moved = 0;
  for (const double d : shift) moved += d != 0.0;
  return moved;
}

/// The share of the points (those whose neighbours lie on a line not counted: their normals, hence
/// signs, are arbitrary under either orientation: the rings of a terrestrial scan's sparse far ground)
/// whose signs agree between two orientations of the same normals.
double sign_agreement(const std::vector<Point3>& a, const std::vector<Point3>& b, const std::vector<LocalFit>& fit) {
  std::size_t same = 0, counted = 0;
  for (std::size_t i = 0; i < a.size(); ++i)
    if (fit[i].spread >= kLinearSpread) same += dot(a[i], b[i]) > 0, ++counted;
  return counted ? static_cast<double>(same) / static_cast<double>(counted) : 1.0;
}

/// sign_agreement() of the viewpoint's orientation `n` with the data's own (the spanning tree, closed
/// parts settled outward), measured on an even sample of the points: a Poisson-disk subset at
/// kViewpointSampleRadius median spacings (about one point in 8 of an even scan; a sparser region keeps
/// more of its points), with its own neighbourhoods (the subset's kViewpointSampleNeighbours nearest) and
/// the points' normals as the viewpoint oriented them.
double sampled_agreement(const std::vector<Point3>& p, const Neighbours& nb, const std::vector<Point3>& n,
                         const std::vector<LocalFit>& fit, std::size_t k, unsigned threads, std::size_t& sample) {
  std::vector<double> nearest(p.size());
  for (std::size_t i = 0; i < p.size(); ++i) nearest[i] = nb.d(i, 0);
  const double spacing = median(nearest);
  const std::vector<char> kept =
      rbf_detail::spaced_subset(p, detail::spatial_order(p), kViewpointSampleRadius * spacing);
  std::vector<Point3> q, qn;
  std::vector<LocalFit> qfit;
  for (std::size_t i = 0; i < p.size(); ++i)
    if (kept[i]) q.push_back(p[i]), qn.push_back(n[i]), qfit.push_back(fit[i]);
  sample = q.size();
  if (q.size() < 64) return 1.0;
  const PointIndex index(q, threads);
  const Neighbours qnb = nearest_neighbours(q, index, std::min({k, kViewpointSampleNeighbours, q.size() - 1}), threads);
  std::vector<Point3> own = qn;
  NormalOptions no;
  no.k = std::min<std::size_t>(qnb.k, 12);
  no.threads = threads;
  no.strict = false;
  rbf_detail::orient_distinct_normals(q, qnb.ids.data(), qnb.k, own, no);
  settle_components(q, qnb, surface_components(qnb, q.size(), nullptr), own, threads);
  return sign_agreement(own, qn, qfit);
}

/// The first k columns of every row (k <= nb.k): the k nearest, when nb's lists are sorted (nearest()).
Neighbours prefix(const Neighbours& nb, std::size_t k) {
  Neighbours out;
  out.k = k;
  const std::size_t n = nb.k ? nb.ids.size() / nb.k : 0;
  out.ids.resize(n * k);
  out.dist.resize(n * k);
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t c = 0; c < k; ++c) {
      out.ids[i * k + c] = nb.ids[i * nb.k + c];
      out.dist[i * k + c] = nb.dist[i * nb.k + c];
    }
  return out;
}

/// prepare_scan()'s test for wider neighbourhoods, put to every stride-th point (kStructureSample of
/// them at most): their k3 nearest, and per row what the verdict needs but the threshold (the k-point
/// fit's residual, the wider fit's, whether the wider neighbourhood holds a second sheet). Computed before
/// the k nearest of every point: `foresees_wider` tells whether the threshold the sample itself gives
/// (its own medians, those of every point deciding later) puts the verdict at "wider" or "every point's".
struct StructureSample {
  Neighbours rows;                 ///< row r: the k3 nearest of point r x stride
  std::vector<double> wide_noise;  ///< row r: the residual of its k3-point fit
  std::vector<std::uint8_t> sheet; ///< row r: its k3 neighbours hold a second sheet (second_sheet)
  bool foresees_wider = false;
  /// +1 wider, -1 not, 0 every point's median decides (the rows' share of wider residuals above the
  /// threshold, kStructureBand standard errors from a half).
  int verdict(double threshold) const {
    const std::size_t n = wide_noise.size();
    std::size_t count = 0;
    for (std::size_t r = 0; r < n; ++r) count += wide_noise[r] > threshold && !sheet[r];
    const double share = static_cast<double>(count) / static_cast<double>(n);
    const double band = kStructureBand * 0.5 / std::sqrt(static_cast<double>(n));
    return share > 0.5 + band ? 1 : share < 0.5 - band ? -1 : 0;
  }
};

StructureSample structure_sample(const std::vector<Point3>& p, const PointIndex& index, std::size_t k,
                                 std::size_t k3, std::size_t stride, unsigned threads) {
  StructureSample s;
  const std::size_t rows = (p.size() + stride - 1) / stride;
  s.rows.k = k3;
  s.rows.ids.resize(rows * k3);
  s.rows.dist.resize(rows * k3);
  s.wide_noise.resize(rows);
  s.sheet.resize(rows);
  std::vector<LocalFit> own(rows);  // the k-point fits (the row's prefix: the k nearest)
  rbf_detail::parallel_chunks(rows, threads, kGrain, [&](std::size_t b, std::size_t e) {
    std::vector<Id> ids;
    std::vector<double> d2;
    for (std::size_t r = b; r < e; ++r) {
      const std::size_t i = r * stride;
      index.nearest(p[i], k3 + 1, ids, &d2);
      fill_row(r, ids, d2, s.rows, i);
      own[r] = fit_neighbourhood(p, s.rows, i, nullptr, r, k);
      s.wide_noise[r] = fit_neighbourhood(p, s.rows, i, nullptr, r).noise;
      s.sheet[r] = second_sheet(p, s.rows, r, i, own[r], s.rows.d(r, k - 1));
    }
  });
  // The forecast: prepare_scan()'s rule on the sample's own medians.
  std::vector<double> ratio(rows), small(rows), dist;
  for (std::size_t r = 0; r < rows; ++r) {
    ratio[r] = own[r].noise / std::max(s.rows.d(r, k - 1), 1e-300);
    small[r] = own[r].noise;
    for (std::size_t c = 0; c < k; ++c) dist.push_back(s.rows.d(r, c));
  }
  const double want = neighbours_wanted(median(ratio));
  const double threshold = std::max(1.5 * median(small), 0.05 * median(dist));
  s.foresees_wider = std::ceil(want) < static_cast<double>(k3) && s.verdict(threshold) >= 0;
  return s;
}

}  // namespace

ScanPoints prepare_scan(const std::vector<Point3>& input, const std::vector<Point3>& normals,
                        const ScanOptions& options, ScanReport* report) {
  const auto t0 = std::chrono::steady_clock::now();
  ScanReport rep;
  auto last_lap = t0;
  const auto lap = [&](const char* step) {  // ScanReport::steps
    const auto now = std::chrono::steady_clock::now();
    rep.steps.emplace_back(step, std::chrono::duration<double>(now - last_lap).count());
    last_lap = now;
  };
  rep.input = input.size();
  if (!normals.empty() && normals.size() != input.size())
    throw InvalidArgument("prepare_scan: " + std::to_string(input.size()) + " points but " +
                          std::to_string(normals.size()) + " normals");
  if (!options.sensors.empty() && options.sensors.size() != input.size())
    throw InvalidArgument("prepare_scan: " + std::to_string(input.size()) + " points but " +
                          std::to_string(options.sensors.size()) + " sensor positions");
  for (std::size_t i = 0; i < input.size(); ++i) {
    if (!is_finite(input[i])) throw InvalidPoint(i, "non-finite coordinate (NaN or infinity)");
    if (!normals.empty() && !is_finite(normals[i])) throw InvalidPoint(i, "non-finite normal");
    if (!options.sensors.empty() && !is_finite(options.sensors[i]))
      throw InvalidPoint(i, "non-finite sensor position");
  }
  if (options.viewpoint && !is_finite(*options.viewpoint))
    throw InvalidArgument("prepare_scan: the viewpoint is not finite");

  // Distinct positions (the first copy of each kept, input order).
  std::vector<std::size_t> order(input.size());
  std::iota(order.begin(), order.end(), std::size_t(0));
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    const Point3 &p = input[a], &q = input[b];
    if (p.x != q.x) return p.x < q.x;
    if (p.y != q.y) return p.y < q.y;
    if (p.z != q.z) return p.z < q.z;
    return a < b;
  });
  std::vector<std::uint8_t> first(input.size(), 0);
  for (std::size_t r = 0; r < order.size(); ++r)
    first[order[r]] = r == 0 || !(input[order[r]] == input[order[r - 1]]);
  std::vector<std::size_t> src;  // input index of each distinct point
  for (std::size_t i = 0; i < input.size(); ++i)
    if (first[i]) src.push_back(i);
  rep.duplicates = input.size() - src.size();
  constexpr std::size_t kMinPoints = 8;
  if (src.size() < kMinPoints)
    throw InvalidArgument("no surface: " + std::to_string(src.size()) + " distinct points (at least " +
                          std::to_string(kMinPoints) + " needed)");
  std::vector<Point3> p(src.size());
  for (std::size_t u = 0; u < src.size(); ++u) p[u] = input[src[u]];
  lap("duplicates");
  if (options.dequantize && options.approximate && options.viewpoint && options.sensors.empty()) {
    rep.dequantized = dequantize_depth(p, *options.viewpoint, options.threads, rep);
    lap("dequantize");
  }

  // Neighbourhoods: k from the data. 16 neighbours first; where the noise is large against their
  // radius, more (the plane residual grows with the noise, the radius with sqrt(k)).
  const unsigned threads = options.threads;
  // A neighbourhood is local: at most half the points (and at least 6) unless options.k says otherwise.
  // On a few dozen points, 16 neighbours of 20 span the whole object: their planes and quadrics are no
  // tangent planes, the noise reads as half a spacing and the two sides as misregistered layers (20
  // points of a sphere gave a box-shaped blob).
  auto clamp_k = [&](std::size_t k) {
    const std::size_t local = options.k ? p.size() - 1 : std::max<std::size_t>(6, p.size() / 2);
    return std::min({k, local, p.size() - 1});
  };
  std::size_t k = clamp_k(options.k ? std::max<std::size_t>(6, options.k) : 16);
  PointIndex index(p, threads);
  // The wider test below (the 48 nearest) asks a sample first (a large scan: every stride-th point).
  // Its rows are computed here, and when the sample foresees the wider neighbourhoods (a depth-quantized
  // or noisy scan), so are the 48 nearest of every point, the k nearest being their prefix (both lists
  // sorted by distance, ties by id: the same lists as their own query), instead of a second query of
  // every point. What is decided below is the same either way; a wrong forecast costs time only.
  const std::size_t k3 = clamp_k(48);
  const std::size_t stride = (p.size() + kStructureSample - 1) / kStructureSample;
  const bool sampled = options.k == 0 && k < k3 && p.size() > 64 && stride > 1;
  StructureSample sample;
  Neighbours wide_all;  // the k3 nearest of every point, when foreseen (else empty)
  if (sampled) {
    sample = structure_sample(p, index, k, k3, stride, threads);
    if (sample.foresees_wider) wide_all = nearest_neighbours(p, index, k3, threads);
  }
  Neighbours nb = wide_all.k ? prefix(wide_all, k) : nearest_neighbours(p, index, k, threads);
  std::vector<LocalFit> fit(p.size());
  auto fit_all = [&](const std::vector<Point3>& pts) {
    fit.assign(pts.size(), LocalFit{});
    rbf_detail::parallel_chunks(pts.size(), threads, kGrain, [&](std::size_t b, std::size_t e) {
      for (std::size_t i = b; i < e; ++i) fit[i] = fit_neighbourhood(pts, nb, i);
    });
  };
  fit_all(p);
  if (options.k == 0) {
    // Two signs that 16 neighbours are too few: noise large against their radius (the plane residual
    // grows with the noise, the radius with sqrt(k)), or structure between their scale and 3x it that a
    // quadric does not follow (depth quantized into layers: each small neighbourhood lies in one layer,
    // and the residual grows with the scale). Sharp edges also grow it, but on few points: medians. A
    // point whose wider neighbourhood holds a parallel second face (a thin part: second_sheet) counts
    // its k-point residual.
    std::vector<double> ratio(p.size()), small(p.size());
    for (std::size_t i = 0; i < p.size(); ++i) {
      ratio[i] = fit[i].noise / std::max(nb.d(i, k - 1), 1e-300);
      small[i] = fit[i].noise;
    }
    const double rho = median(ratio), noise_small = median(small);
    const double want = neighbours_wanted(rho);
    std::size_t k2 = clamp_k(static_cast<std::size_t>(std::min(double(kMaxNeighbours), std::max(16.0, std::ceil(want)))));
    if (k2 < 48 && p.size() > 64) {
      // Only structure that matters against the spacing (a clean curved surface also fits a quadric a
      // little worse at a larger scale): the wider fits' median residual above `threshold`.
      const double threshold = std::max(1.5 * noise_small, 0.05 * median(nb.dist));
      // On a large scan the question is first put to an even subsample (every stride-th point, at most
      // kStructureSample): the share of its wider residuals above the threshold. Clearly away from a half
      // (kStructureBand standard errors of a sampled share), the subsample answers and the wider
      // neighbourhoods of every point are computed only when wanted (on a clean scan of 10^6 points the
      // wider queries and fits of all were 9.6 of the preparation's 25 s); near a half (a scan at the
      // threshold, such as the quantized office capture), every point's, as on a small scan: the same
      // answer as the whole's median but with a chance of about 10^-6.
      int verdict = 0;  // +1 wider, -1 not, 0 every point's median decides
      if (sampled) verdict = sample.verdict(threshold);
      if (verdict == 0) {
        Neighbours wide = wide_all.k ? std::move(wide_all) : nearest_neighbours(p, index, k3, threads);
        std::vector<LocalFit> wide_fit(p.size());
        rbf_detail::parallel_chunks(p.size(), threads, kGrain, [&](std::size_t b, std::size_t e) {
          for (std::size_t i = b; i < e; ++i) wide_fit[i] = fit_neighbourhood(p, wide, i);
        });
        std::vector<double> big(p.size());
        for (std::size_t i = 0; i < p.size(); ++i)
          big[i] = second_sheet(p, wide, i, i, fit[i], nb.d(i, k - 1)) ? fit[i].noise : wide_fit[i].noise;
        if (median(big) > threshold) {
          k = k2 = k3;  // these neighbourhoods and fits are the ones wanted: kept, not computed again
          nb = std::move(wide);
          fit.swap(wide_fit);
        }
      } else if (verdict > 0) {
        k = k2 = k3;
        nb = wide_all.k ? std::move(wide_all) : nearest_neighbours(p, index, k, threads);
        fit_all(p);
      }
    }
    if (k2 > k) {
      k = k2;
      nb = nearest_neighbours(p, index, k, threads);
      fit_all(p);
    }
  }
  wide_all = Neighbours{};  // (a forecast the verdict did not follow: its lists given back)
  sample = StructureSample{};
  rep.k = k;
  lap("neighbours");

  std::vector<Point3> set_aside;
  // Outliers: set aside, then the neighbourhoods of the inliers; again, up to three rounds, while some
  // are found: outliers whose neighbours were other outliers (spread over the box) look ordinary among
  // them, and stand out once those are gone (their neighbours are then surface points).
  // (A later round computes again only the points whose inputs changed: find_outliers, `stale`.)
  OutlierRound last;
  std::vector<std::uint8_t> stale;
  for (int round = 0; round < 3 && options.remove_outliers; ++round) {
    std::vector<double> noise(p.size());
    for (std::size_t i = 0; i < p.size(); ++i) noise[i] = fit[i].noise;
    const std::vector<std::uint8_t> outlier =
        find_outliers(p, index, nb, noise, threads, last, stale.empty() ? nullptr : &stale);
    std::vector<std::size_t> keep;
    for (std::size_t u = 0; u < p.size(); ++u)
      if (!outlier[u]) keep.push_back(u);
      else set_aside.push_back(p[u]);
    if (keep.size() == p.size()) break;
    rep.outliers += p.size() - keep.size();
    if (keep.size() < kMinPoints)
      throw InvalidArgument("no surface: " + std::to_string(keep.size()) + " of " +
                            std::to_string(keep.size() + rep.outliers) +
                            " distinct points agree on a surface, the others are outliers");
    std::vector<Point3> q(keep.size());
    std::vector<std::size_t> s(keep.size());
    for (std::size_t r = 0; r < keep.size(); ++r) q[r] = p[keep[r]], s[r] = src[keep[r]];
    p.swap(q);
    src.swap(s);
    index = PointIndex(p, threads);
    for (std::size_t r = 0; r < keep.size(); ++r) last.volume[r] = last.volume[keep[r]];
    last.volume.resize(keep.size());
    if (clamp_k(k) == k) {
      stale = refresh_after_removal(p, index, keep, nb, fit, threads);
    } else {
      k = clamp_k(k);
      nb = nearest_neighbours(p, index, k, threads);
      fit_all(p);
      stale.clear();  // every row new: every point computed
    }
  }
  if (options.remove_outliers) lap("outliers");
  std::size_t collinear = 0;
  for (const LocalFit& f : fit) collinear += f.collinear;
  if (collinear == p.size())
    throw InvalidArgument("no surface: every neighbourhood of the " + std::to_string(p.size()) +
                          " points is collinear (the points lie on a line)");
  // The noise per region: each point's residual is one neighbourhood's (itself noisy); the median over the
  // neighbourhood (the point included) is the region's. ScanReport::noise is the median over the points.
  // `residual`: each point's fit residual at orientation time (the smooth points, the sharp edges).
  std::vector<double> region_noise(p.size()), region_nn(p.size()), residual(p.size());
  for (std::size_t i = 0; i < p.size(); ++i) residual[i] = fit[i].noise;
  {
    const std::vector<double>& noise = residual;
    rep.noise = median(noise);
    rbf_detail::parallel_chunks(p.size(), threads, kGrain, [&](std::size_t b, std::size_t e) {
      std::vector<double> a, c;
      for (std::size_t i = b; i < e; ++i) {
        a.assign(1, noise[i]);
        c.assign(1, nb.d(i, 0));
        for (std::size_t j = 0; j < nb.k; ++j) {
          a.push_back(noise[nb.at(i, j)]);
          c.push_back(nb.d(nb.at(i, j), 0));
        }
        region_noise[i] = median_in_place(a);
        region_nn[i] = median_in_place(c);
      }
    });
  }

  std::vector<Point3> n(p.size());
  for (std::size_t i = 0; i < p.size(); ++i) n[i] = fit[i].normal;

  // Orientation.
  const bool given = !normals.empty();
  std::vector<std::uint8_t> undecided(p.size(), 0);
  bool need_tree = !given && !options.viewpoint && options.sensors.empty();
  if (given) {
    rep.orientation = OrientationSource::Given;
    for (std::size_t i = 0; i < p.size(); ++i) {
      const Point3 g = normals[src[i]];
      const double len = norm(g);
      const double c = len > 0 ? dot(n[i], g) / len : 0.0;
      if (len > 0 && std::abs(c) < 0.5) ++rep.repaired;  // more than 60 degrees off the tangent plane's normal
      if (!(len > 0) || std::abs(c) < 0.05) undecided[i] = 1;
      if (c < 0) n[i] = -n[i];
    }
  } else if (options.viewpoint || !options.sensors.empty()) {
    rep.orientation = options.sensors.empty() ? OrientationSource::Viewpoint : OrientationSource::Sensors;
    for (std::size_t i = 0; i < p.size(); ++i) {
      const Point3 eye = options.sensors.empty() ? *options.viewpoint : options.sensors[src[i]];
      const Point3 ray = eye - p[i];
      const double len = norm(ray);
      const double c = len > 0 ? dot(n[i], ray) / len : 0.0;
      if (std::abs(c) < 0.05) undecided[i] = 1;  // seen edge-on: the neighbours decide
      if (c < 0) n[i] = -n[i];
    }
    // A viewpoint the data contradict (a merged multi-view cloud with PCL's default VIEWPOINT 0 0 0, a
    // wrong sensor): one view cannot see every side of a closed object, so the orientation it gives
    // differs from the data's own (the spanning tree, closed parts settled outward) on a large share of
    // the points, whatever the sign of each; or neighbours along the surface get opposite signs.
    // A viewpoint inside the data's box (a room around the sensor) sees every side: only the second test.
    Point3 lo = p[0], hi = p[0];
    for (const Point3& q : p)
      for (std::size_t a = 0; a < 3; ++a) lo[a] = std::min(lo[a], q[a]), hi[a] = std::max(hi[a], q[a]);
    bool outside = false;
    if (options.sensors.empty())
      for (std::size_t a = 0; a < 3; ++a) outside = outside || (*options.viewpoint)[a] < lo[a] || (*options.viewpoint)[a] > hi[a];
    std::vector<Point3> own;
    auto own_orientation = [&]() {  // the data's own orientation of every point: its agreement with n
      own = n;
      NormalOptions no;
      no.k = std::min<std::size_t>(k, 12);
      no.threads = threads;
      no.strict = false;
      rbf_detail::orient_distinct_normals(p, nb.ids.data(), nb.k, own, no);
      settle_components(p, nb, surface_components(nb, p.size(), nullptr), own, threads);
      return sign_agreement(own, n, fit);
    };
    // The agreement, first on a sample of the points when they are many: it answers when clearly away
    // from the limit (kViewpointBand); near it, or when the viewpoint is rejected (`own` then orients
    // the points, and the message gives the whole's share), every point's.
    double agree = 1.0;
    if (outside && p.size() >= kViewpointSampleMin) {
      agree = sampled_agreement(p, nb, n, fit, k, threads, rep.viewpoint_sample);
      if (rep.viewpoint_sample < 64 || std::abs(std::max(agree, 1 - agree) - kViewpointAgree) < kViewpointBand)
        agree = own_orientation();
    } else if (outside) {
      agree = own_orientation();
    }
    const double dis = disagreement(p, nb, n, fit, threads);
    bool rejected = dis > 0.05 || std::max(agree, 1 - agree) < kViewpointAgree;
    if (rejected && outside && own.empty()) {
      agree = own_orientation();
      rejected = dis > 0.05 || std::max(agree, 1 - agree) < kViewpointAgree;
    }
    if (!own.empty()) rep.viewpoint_sample = 0;  // every point's orientation decided
    if (rejected) {
      rep.viewpoint_rejected = true;
      std::ostringstream why;
      why << "the " << (options.sensors.empty() ? "viewpoint" : "sensor positions") << " orient only "
          << std::round(1000 * std::max(agree, 1 - agree)) / 10
          << "% of the points as the data's own orientation does (at least 90% expected of one view), "
          << std::round(1000 * dis) / 10 << "% of the neighbour pairs along the surface opposite (at most 5%): "
             "the data are not seen from there; normals oriented without it";
      rep.viewpoint_note = why.str();
      std::fill(undecided.begin(), undecided.end(), 0);
      rep.orientation = OrientationSource::Estimated;
      if (outside) n.swap(own);
      else need_tree = true;
    }
  }
  if (need_tree) {
    rep.orientation = OrientationSource::Estimated;
    NormalOptions no;
    no.k = std::min<std::size_t>(k, 12);
    no.threads = threads;
    no.strict = false;
    no.min_link = 0.1;
    const OrientationReport orep = rbf_detail::orient_distinct_normals(p, nb.ids.data(), nb.k, n, no);
    rep.ambiguous += orep.ambiguous;
    const std::vector<Id> parts = surface_components(nb, p.size(), nullptr);
    rep.regions_flipped = repair_regions(p, nb, parts, residual, rep.noise, n, threads);
    settle_components(p, nb, parts, n, threads);
  }
  std::size_t undecided_count = 0;
  for (const std::uint8_t u : undecided) undecided_count += u;
  rep.ambiguous += undecided_count;
  // Votes: the undecided take their neighbours' majority; isolated wrong signs (a flipped given normal,
  // a tree step across a sharp edge) are outvoted by a strong majority.
  for (int pass = 0; pass < 3; ++pass) {
    const std::size_t flips = vote_signs(p, nb, n, undecided_count ? &undecided : nullptr, 0.8, threads);
    if (given) rep.repaired += flips;
    else rep.ambiguous += flips;
    std::fill(undecided.begin(), undecided.end(), 0);
    undecided_count = 0;
    if (flips == 0) break;
  }

  lap("orientation");  // (with the per-region noise above)

  // Misregistered layers merged (merge_layers), before the projection smooths what is left.
  // The second pass examines only the points whose neighbours the first one may have changed: those it
  // moved and those with a moved point (before or after its move) within the reach of their examined
  // neighbours; every other point would see exactly its first-pass neighbours and stay (the same result
  // as examining all, at a fraction of the queries: on a clean scan almost nothing moves).
  // `layered`: the points merge_layers moved between two layers (not as noise), for the projection below.
  std::vector<std::uint8_t> layered(p.size(), 0);
  if (options.approximate) {
    std::vector<double> shift, reach, total(p.size(), 0.0);
    std::vector<std::uint8_t> again;
    for (int pass = 0; pass < 2; ++pass) {
      if (pass > 0) index = PointIndex(p, threads);
      // (pass 0: nb holds the neighbours of these positions; pass 1: the points moved since)
      if (merge_layers(p, n, region_noise, index, nb, pass == 0, threads, shift, reach,
                       pass > 0 ? &again : nullptr, &layered) == 0)
        break;
      std::vector<Point3> ends;  // the moved points' positions before and after
      for (std::size_t i = 0; i < p.size(); ++i)
        if (shift[i] != 0.0) ends.push_back(p[i]), ends.push_back(p[i] + shift[i] * n[i]);
      for (std::size_t i = 0; i < p.size(); ++i) p[i] = p[i] + shift[i] * n[i], total[i] += shift[i];
      if (pass == 1) break;
      const PointIndex moved(ends, threads);
      again.assign(p.size(), 0);
      rbf_detail::parallel_chunks(p.size(), threads, kGrain, [&](std::size_t b, std::size_t e) {
        std::vector<Id> one;
        std::vector<double> d2;
        for (std::size_t i = b; i < e; ++i) {
          if (shift[i] != 0.0) {
            again[i] = 1;
            continue;
          }
          moved.nearest(p[i], 1, one, &d2);
          again[i] = !d2.empty() && d2[0] <= reach[i] * reach[i];
        }
      });
    }
    for (const double t : total) rep.merged += t != 0.0;
    lap("layers");
  }

  // Sharp edges (estimated normals, clean data with no misregistered layers to speak of): a point whose
  // neighbourhood straddles two faces gets a tangent plane between them, and a sign that cannot agree
  // with both; it takes the oriented normal of the decided neighbour on whose tangent plane it lies (its
  // own face's). (The residuals are the fits' before the layers' merging: on such data it moved almost
  // nothing.)
  if (rep.orientation != OrientationSource::Given) {
    std::vector<double> nearest(p.size());
    for (std::size_t i = 0; i < p.size(); ++i) nearest[i] = nb.d(i, 0);
    if (rep.noise <= kEdgeCleanNoise * median(nearest) && rep.merged <= p.size() / 1000)
      rep.edge_normals = edge_normals_from_faces(p, nb, residual, rep.noise, n, threads);
  }
  // Approximation: the projection onto the local quadrics of each point's own side (twice where the data
  // are noisy: the second fit sees the smoother points), once the normals are oriented; the normals are
  // then those of the quadrics at the projected points, with the signs decided.
  if (options.approximate) {
    const std::vector<Point3> before = p;
    std::vector<double> nearest(p.size());
    for (std::size_t i = 0; i < p.size(); ++i) nearest[i] = nb.d(i, 0);
    const double scale = median(nearest);  // the spacing
    // The overlaps of misregistered views: points merged between two layers (`layered`; not moves
    // within noise) most of whose neighbours were merged so too (`core`; a real scan's few merges, at
    // steps and creases, have fewer: under 40% of their neighbours on the shipped scans but 3 points of
    // lidar_cars, over 60% for most of an overlap's), and the points beside them (`near_layers`). Each
    // point's middle between the layers depends on its own cylinder's points, and a 16-point fit, in one
    // layer or the other, keeps that scatter (pits all over the overlap): there the fits see the
    // kMaxNeighbours nearest (below) whatever their residual.
    std::vector<std::uint8_t> core(p.size(), 0), near_layers(p.size(), 0);
    for (std::size_t i = 0; i < p.size(); ++i) {
      if (!layered[i]) continue;
      std::size_t count = 0;
      for (std::size_t c = 0; c < nb.k; ++c) count += layered[nb.at(i, c)];
      core[i] = 2 * count >= nb.k;
    }
    for (std::size_t i = 0; i < p.size(); ++i) {
      bool any = core[i] != 0;
      for (std::size_t c = 0; c < nb.k && !any; ++c) any = core[nb.at(i, c)] != 0;
      near_layers[i] = any;
    }
    // Passes: a second where the noise exceeds 0.1 spacings, four above 0.5 (three until session 41: the
    // fourth halved the handles of pig with noise of 2 spacings, -94 -> -50), the noise being the
    // larger of the scan's median and the point's region's (a noisy region gets more passes than the
    // scan as a whole, never fewer).
    auto passes_at = [&](std::size_t i) {
      const double noise = std::max(region_noise[i], rep.noise);
      return noise > 0.5 * scale ? 4 : noise > 0.1 * scale ? 2 : 1;
    };
    int passes = 1;
    for (std::size_t i = 0; i < p.size(); ++i) passes = std::max(passes, passes_at(i));
    // Wider neighbourhoods where the region is noisy against the scan's k (the rule that chose k, step 2,
    // applied per region: a misregistered overlap or a grazing part of a clean scan): the point's fits
    // see up to kMaxNeighbours, as many as its region's noise asks for.
    std::vector<std::size_t> wide_row(p.size(), kNoRow), wide_use(p.size(), 0);
    Neighbours wide;
    if (options.k == 0) {
      std::vector<std::uint8_t> flagged(p.size(), 0);
      std::size_t rows = 0, kw = 0;
      for (std::size_t i = 0; i < p.size(); ++i) {
        if (near_layers[i]) {  // an overlap's merged layers: the widest fits, kept whatever their residual
          flagged[i] = 1;
          wide_row[i] = rows++;
          wide_use[i] = clamp_k(kMaxNeighbours);
          kw = std::max(kw, wide_use[i]);
          continue;
        }
        const double rho = region_noise[i] / std::max(nb.d(i, nb.k - 1), 1e-300);
        const double want = neighbours_wanted(rho);
        if (!(want >= 1.5 * static_cast<double>(nb.k))) continue;
        if (!(region_noise[i] > 2 * rep.noise)) continue;  // not where the whole scan is as noisy
        if (!(region_noise[i] > 0.1 * region_nn[i])) continue;  // nor where it is clean (step 7's passes)
        const std::size_t use = clamp_k(static_cast<std::size_t>(std::min(double(kMaxNeighbours), std::ceil(want))));
        if (use <= nb.k) continue;
        flagged[i] = 1;
        wide_row[i] = rows++;
        wide_use[i] = use;
        kw = std::max(kw, use);
      }
      if (rows) {
        const PointIndex now(p, threads);
        wide.k = kw;
        wide.ids.resize(rows * kw);
        wide.dist.resize(rows * kw);
        sweep_nearest(p, now, kw + 1, threads, &flagged,
                      [&](std::size_t i, const std::vector<Id>& ids, const std::vector<double>& d2) {
                        fill_row(wide_row[i], ids, d2, wide, i);
                      });
      }
    }
    auto fit_at = [&](std::size_t i) {
      return wide_row[i] == kNoRow ? fit_neighbourhood(p, nb, i, &n)
                                   : fit_neighbourhood(p, wide, i, &n, wide_row[i], wide_use[i]);
    };
    for (int pass = 0; pass < passes; ++pass) {
      rbf_detail::parallel_chunks(p.size(), threads, kGrain, [&](std::size_t b, std::size_t e) {
        for (std::size_t i = b; i < e; ++i) {
          if (!(pass < passes_at(i))) continue;
          fit[i] = fit_at(i);
          if (pass == 0 && wide_row[i] != kNoRow) {
            // Noise keeps its scale when the neighbourhood widens; shape (an edge, a corner, clutter)
            // fits worse the wider it is seen: there the point keeps its k.
            const LocalFit own = fit_neighbourhood(p, nb, i, &n);
            if (!near_layers[i] && fit[i].noise > kWideningGrowth * own.noise) {
              wide_row[i] = kNoRow;
              fit[i] = own;
            }
          }
        }
      });
      for (std::size_t i = 0; i < p.size(); ++i)
        if (pass < passes_at(i)) p[i] = fit[i].projected;
    }
    for (const std::size_t r : wide_row) rep.widened += r != kNoRow;
    rbf_detail::parallel_chunks(p.size(), threads, kGrain, [&](std::size_t b, std::size_t e) {
      for (std::size_t i = b; i < e; ++i) fit[i] = fit_at(i);
    });
    for (std::size_t i = 0; i < p.size(); ++i) n[i] = fit[i].normal;
    std::vector<double> d(p.size());
    for (std::size_t i = 0; i < p.size(); ++i) d[i] = norm(p[i] - before[i]);
    rep.moved = median(d);
    lap("projection");
  }

  std::vector<double> nn(p.size()), local(p.size());
  for (std::size_t i = 0; i < p.size(); ++i) {
    local[i] = local_spacing(nb, i);
    nn[i] = nb.d(i, 0);
  }
  rep.spacing = median(nn);
  rep.resolution = std::max(rep.spacing, 2 * rep.noise);
  // Thinning to the resolution: where the noise exceeds the spacing, the projected points carry no
  // detail finer than the resolution, and clusters of them closer than that only make the interpolant
  // fold between them (small handles at the default precision). A Poisson-disk subset (input order) at
  // half the resolution keeps one point per such cluster.
  //
  // Per region: the resolution of point i is max(its region's spacing, 2 x its region's noise) and the
  // rule applies where that exceeds 1.2 x the region's spacing (a noisy part of a cleaner scan, the
  // overlap of misregistered views, whose two layers give their neighbourhoods' quadrics a residual of
  // about half their distance); where the whole scan is that noisy, the scan's resolution as before.
  std::vector<char> kept(p.size(), 1);
  std::vector<double> radius(p.size(), 0.0);  // of the Poisson disk; 0: not thinned
  const bool thin_all = options.approximate && rep.resolution > 1.2 * rep.spacing;
  if (thin_all) {
    std::vector<std::size_t> visit(p.size());
    std::iota(visit.begin(), visit.end(), std::size_t(0));
    kept = rbf_detail::spaced_subset(p, visit, 0.5 * rep.resolution);
    std::fill(radius.begin(), radius.end(), 0.5 * rep.resolution);
  } else if (options.approximate) {
    // Greedy in input order over each point's neighbours (the Poisson disk of radius
    // 0.5 x resolution_i is within its k nearest: resolution_i is a few spacings at most where k grew
    // with the noise); a point whose disk holds a point kept before it is left out.
    for (std::size_t i = 0; i < p.size(); ++i)  // resolution_i = 2 x noise_i above 1.2 x spacing_i
      if (region_noise[i] > 0.6 * region_nn[i]) radius[i] = region_noise[i];
    for (std::size_t i = 0; i < p.size(); ++i) {
      if (radius[i] == 0) continue;
      for (std::size_t c = 0; c < nb.k && kept[i]; ++c) {
        const Id j = nb.at(i, c);
        if (j < i && kept[j] && norm(p[j] - p[i]) < radius[i]) kept[i] = 0;
      }
    }
  }
  ScanPoints out;
  for (std::size_t i = 0; i < p.size(); ++i) {
    if (!kept[i]) continue;
    out.points.push_back(p[i]);
    out.normals.push_back(n[i]);
    out.spacing.push_back(std::max(local[i], radius[i]));
  }
  out.set_aside = std::move(set_aside);
  rep.thinned = p.size() - out.points.size();
  lap("thinning");
  rep.kept = out.points.size();
  rep.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  if (report) *report = rep;
  return out;
}

std::string describe(const ScanReport& r) {
  std::ostringstream s;
  s.precision(3);
  const char* source = r.orientation == OrientationSource::Given       ? "the input's normals"
                       : r.orientation == OrientationSource::Viewpoint ? "the viewpoint"
                       : r.orientation == OrientationSource::Sensors   ? "the sensor positions"
                                                                        : "estimated (spanning tree)";
  s << "scan: " << r.kept << " of " << r.input << " points kept (" << r.duplicates << " duplicates, "
    << r.outliers << " outliers set aside); " << r.k << " neighbours; spacing " << r.spacing << ", noise "
    << r.noise << " (" << (r.spacing > 0 ? r.noise / r.spacing : 0) << " spacings), points moved by "
    << r.moved << " (median)";
  if (r.dequantized)
    s << ", " << r.dequantized << " moved within their depth step (" << r.quantized << " quantized in " << r.levels
      << " levels, steps " << r.step_min << " to " << r.step_max << ")";
  if (r.merged) s << ", " << r.merged << " moved to the middle of misregistered layers";
  if (r.widened) s << ", " << r.widened << " projected over wider neighbourhoods (noisy regions)";
  if (r.thinned) s << ", " << r.thinned << " thinned to the resolution " << r.resolution;
  s << "; normals from " << source;
  if (r.repaired) s << ", " << r.repaired << " given normals repaired";
  if (r.regions_flipped) s << ", " << r.regions_flipped << " flipped with their regions across sharp edges";
  if (r.edge_normals) s << ", " << r.edge_normals << " on sharp edges given their face's normal";
  if (r.ambiguous) s << ", " << r.ambiguous << " signs ambiguous";
  if (r.viewpoint_rejected) s << "; " << r.viewpoint_note;
  return s.str();
}

}  // namespace vitri
