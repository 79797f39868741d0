// Marching tetrahedra, the pure parts (Bloomenthal 1994; Crespin 2003, section 3.5).
//
// Orientation follows from the positive orientation of live tetrahedra:
//   lone vertex i, (i, j, k, l) an even permutation of (0, 1, 2, 3):
//     triangle (e_ij, e_ik, e_il) faces away from i  -> as is when i is negative, reversed when positive
//   pair a, b negative, c, d positive, (a, b, c, d) even:
//     quad (e_ac, e_ad, e_bd, e_bc) faces the positive side
// Vertex placement: Illinois regula falsi on each crossed edge, with Newton steps (from the gradient)
// while they stay inside the bracket, all edges in lockstep so that each iteration is one batch call of
// f (value and gradient: the gradient at the accepted point is the vertex normal). The result is clamped
// inside the edge.
#include "marching.hpp"

#include <algorithm>
#include <cmath>

namespace vitri::marching {

namespace {

// Even permutations (i, j, k, l) starting with each lone vertex i.
constexpr int kLone[4][4] = {{0, 1, 2, 3}, {1, 0, 3, 2}, {2, 3, 0, 1}, {3, 2, 1, 0}};

std::array<int, 2> crossed(const std::array<bool, 4>& negative, int a, int b) {
  return negative[a] ? std::array<int, 2>{a, b} : std::array<int, 2>{b, a};
}

}  // namespace

CellPolygon march_tetrahedron(const std::array<bool, 4>& negative) {
  CellPolygon poly;
  int count = 0;
  for (const bool n : negative) count += n ? 1 : 0;
  if (count == 1 || count == 3) {
    int lone = 0;
    for (int i = 0; i < 4; ++i)
      if (negative[i] == (count == 1)) lone = i;
    const int* p = kLone[lone];
    poly.corners = 3;
    poly.edges[0] = crossed(negative, p[0], p[1]);
    poly.edges[1] = crossed(negative, p[0], count == 1 ? p[2] : p[3]);
    poly.edges[2] = crossed(negative, p[0], count == 1 ? p[3] : p[2]);
  } else if (count == 2) {
    int a = -1, b = -1, c = -1, d = -1;
    for (int i = 0; i < 4; ++i) {
      if (negative[i]) (a < 0 ? a : b) = i;
      else (c < 0 ? c : d) = i;
    }
    // (a, b, c, d) with a < b, c < d: make it an even permutation (swap c, d if odd).
    const int perm[4] = {a, b, c, d};
    int inversions = 0;
    for (int i = 0; i < 4; ++i)
      for (int j = i + 1; j < 4; ++j) inversions += perm[i] > perm[j] ? 1 : 0;
    if (inversions % 2) std::swap(c, d);
    poly.corners = 4;
    poly.edges = {{{a, c}, {a, d}, {b, d}, {b, c}}};
  }
  return poly;
}

int quad_split(const Point3& q0, const Point3& q1, const Point3& q2, const Point3& q3) {
  return squared_distance(q0, q2) <= squared_distance(q1, q3) ? 0 : 1;
}

namespace {

// The Illinois + Newton iteration state of one edge.
struct Bracket {
  double a = 0, b = 1, ga = 0, gb = 0, last = -1, gtol = 0, newton = -1, t = 0;
  signed char side = 0;
};

Point3 at(const Crossing& c, double t) { return c.pos_point + t * (c.neg_point - c.pos_point); }

// One iteration's update of bracket s from g = f(at(t)) and its gradient; true when the edge is done.
bool step(Bracket& s, const Crossing& c, double g, const Point3& grad, double tol) {
  if (std::abs(g) <= s.gtol || std::isnan(g)) return true;  // NaN: keep the estimate (inside the bracket)
  if (g > 0.0) {
    s.a = s.t;
    s.ga = g;
    if (s.side == 1) s.gb *= 0.5;
    s.side = 1;
  } else {
    s.b = s.t;
    s.gb = g;
    if (s.side == -1) s.ga *= 0.5;
    s.side = -1;
  }
  const bool done = s.b - s.a <= tol || std::abs(s.t - s.last) <= 0.5 * tol;
  // Next point: the Newton step from t when it stays inside the bracket, else the Illinois step.
  const double slope = dot(grad, c.neg_point - c.pos_point);  // df/dt
  s.newton = slope < 0.0 && std::isfinite(slope) ? s.t - g / slope : -1.0;
  return done;
}

}  // namespace

std::size_t place_crossings(const ImplicitFunction& f, const RootSettings& settings,
                            const std::vector<Crossing>& crossings, std::vector<Placement>& out) {
  const std::size_t n = crossings.size();
  out.assign(n, Placement{});
  std::vector<std::uint32_t> active;
  std::vector<Bracket> state(n);
  for (std::size_t i = 0; i < n; ++i) {
    const Crossing& c = crossings[i];
    double t = settings.zero_offset;
    if (c.pos_value != 0.0) t = std::clamp(c.pos_value / (c.pos_value - c.neg_value), settings.min_t, 1.0 - settings.min_t);
    out[i].t = t;
    out[i].x = at(c, t);
    if (c.pos_value == 0.0 || !settings.root_finding) continue;
    Bracket& s = state[i];
    s.ga = c.pos_value;
    s.gb = c.neg_value;
    s.gtol = settings.tolerance * (s.ga - s.gb);
    active.push_back(static_cast<std::uint32_t>(i));
  }
  std::size_t evaluations = 0;
  std::vector<Point3> pts, grads;
  std::vector<double> vals;
  for (int it = 0; it < settings.max_iterations && !active.empty(); ++it) {
    pts.resize(active.size());
    vals.resize(active.size());
    grads.resize(active.size());
    for (std::size_t k = 0; k < active.size(); ++k) {
      Bracket& s = state[active[k]];
      const Crossing& c = crossings[active[k]];
      double t = s.a + (s.b - s.a) * (s.ga / (s.ga - s.gb));
      if (s.newton > s.a && s.newton < s.b) t = s.newton;
      if (it == 0 && c.guess > 0.0 && c.guess < 1.0) t = c.guess;
      if (!(t > s.a && t < s.b)) t = 0.5 * (s.a + s.b);  // safeguard (underflow, rounding)
      s.t = t;
      pts[k] = at(c, t);
    }
    f.values_gradients(pts.data(), pts.size(), vals.data(), grads.data());
    evaluations += pts.size();
    std::size_t keep = 0;
    for (std::size_t k = 0; k < active.size(); ++k) {
      const std::uint32_t i = active[k];
      Bracket& s = state[i];
      const bool done = step(s, crossings[i], vals[k], grads[k], settings.tolerance);
      s.last = s.t;
      const double tc = std::clamp(s.t, settings.min_t, 1.0 - settings.min_t);
      out[i] = Placement{at(crossings[i], tc), grads[k], tc, tc == s.t};
      if (!done) active[keep++] = i;
    }
    active.resize(keep);
  }
  return evaluations;
}

}  // namespace vitri::marching
