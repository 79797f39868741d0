// Tests of vitri::Mesher: real models through the RBF (topology, closeness to the input), levels of
// detail, dynamic edits (watertight, on the edited surface, close to a fresh mesh, bounded growth).
#include <catch2/catch.hpp>

#include "support/surface_metrics.hpp"
#include "vitri/core/error.hpp"
#include "vitri/io/io.hpp"
#include "vitri/mesher.hpp"
#include "vitri/testing/mesh_metrics.hpp"

#include <algorithm>
#include <cmath>
#include <random>
#include <string>

using namespace vitri;

namespace {

const std::string kData = VITRI_DATA_DIR;

using test::metrics_of;

void require_closed(const SurfaceMesh& m) {
  const MeshMetrics mm = metrics_of(m);
  INFO("V " << mm.vertices << " F " << mm.triangles << " boundary " << mm.boundary_edges << " nonmanifold e/v "
            << mm.non_manifold_edges << "/" << mm.non_manifold_vertices << " inconsistent " << mm.inconsistent_edges
            << " degenerate " << mm.degenerate_triangles << " zero-area " << mm.zero_area_triangles
            << " duplicates " << mm.duplicate_vertices);
  REQUIRE(mm.closed_manifold());
  REQUIRE(mm.signed_volume > 0.0);
}

/// Largest first-order distance |f| / |grad f| of the mesh vertices to the surface of f.
double max_surface_distance(const SurfaceMesh& m, const ImplicitFunction& f) {
  Eigen::MatrixXd V;
  Eigen::MatrixXi F;
  to_eigen(m, V, F);
  return surface_distance(V, f).max;
}

/// A small model at the paper's Table 2 scale (25 constraints): the center of an ellipsoid (index 0,
/// value -0.5), 18 points of its surface (value 0) and 6 points outside it on the axes (value +1), which
/// keep f positive far away so that the surface stays well inside the domain box.
Constraints small_model() {
  Constraints c;
  c.add({0.0, 0.0, 0.0}, -0.5);
  const double golden = 3.14159265358979323846 * (3.0 - std::sqrt(5.0));
  for (int i = 0; i < 18; ++i) {
    const double z = 1.0 - 2.0 * (i + 0.5) / 18.0, r = std::sqrt(1.0 - z * z), phi = golden * i;
    c.add({1.0 * r * std::cos(phi), 0.8 * r * std::sin(phi), 0.6 * z}, 0.0);
  }
  for (int k = 0; k < 3; ++k)
    for (const double s : {-2.0, 2.0}) {
      Point3 p{0.0, 0.0, 0.0};
      p[static_cast<std::size_t>(k)] = s;
      c.add(p, 1.0);
    }
  return c;
}

}  // namespace

namespace {

struct ModelCase {
  const char* file;
  std::size_t max_constraints;  // subsampled to keep the sanitizer run short
  double precision;             // relative to the diagonal
  long long euler;
};

void check_model_with(const ModelCase& c, MesherOptions o) {
  INFO(c.file);
  const TriangleMesh in = read_mesh(kData + "/" + c.file);
  o.constraint_build.max_constraints = c.max_constraints;
  Mesher mesher = Mesher::from_mesh(in.V, in.F, o);
  const double precision = c.precision * mesher.diagonal();
  REQUIRE(mesher.refine(precision));
  const SurfaceMesh& m = mesher.surface();
  require_closed(m);
  const MeshMetrics mm = metrics_of(m);
  REQUIRE(mm.euler_characteristic == c.euler);
  REQUIRE(mm.components == 1);
  // The vertices are on the fitted surface: root-finder vertices to 1e-4 of an edge, the crossings of
  // zero vertices that could not be collapsed at 5% of an edge (edges < 2 precision); the on-surface
  // constraints are near the mesh.
  REQUIRE(max_surface_distance(m, mesher.function()) <= 0.1 * precision);
  const MeshDistance md(m);
  double worst = 0.0;
  const Constraints& cs = mesher.constraints();
  for (std::size_t i = 0; i < cs.size(); ++i)
    if (cs.values[i] == 0.0) worst = std::max(worst, md.distance(cs.points[i]));
  REQUIRE(worst <= precision);
  // Every on-surface constraint whose crossings could be collapsed is a mesh vertex exactly.
  REQUIRE(mesher.stats().polygonizer.zero_snapped > 0);
}

void check_model(const ModelCase& c) { check_model_with(c, {}); }

}  // namespace

// Stated precisions: at these the RBF surface of each model has the model's topology.
TEST_CASE("real models: watertight 2-manifold with the model's Euler characteristic", "[mesher]") {
  check_model(GENERATE(ModelCase{"hand.off", 1500, 0.03, 2}, ModelCase{"bunny.off", 1500, 0.03, 2},
                       ModelCase{"knot1.off", 1500, 0.03, 0}));
}

// The global function's batch kernels on a round's new vertices, one helper batch at a time
// (values_ahead.hpp) or in the round's batch: the same values, so the same mesh bit for bit.
TEST_CASE("MesherOptions::threads: one field for every phase, and the same mesh on any count", "[mesher]") {
  MesherOptions o;
  o.polygonizer.threads = 5;
  CHECK(with_threads_applied(o).polygonizer.threads == 5);  // 0: each phase's own field decides
  CHECK(with_threads_applied(o).local.threads == 0);
  o.threads = 3;
  const MesherOptions a = with_threads_applied(o);
  for (unsigned t : {a.polygonizer.threads, a.local.threads, a.rbf.threads, a.constraint_build.threads,
                     a.constraint_build.normals.threads, a.scan.threads})
    CHECK(t == 3);
  // The global function's refinement evaluates ahead on a helper thread with 2 threads, not with 1 (the
  // field reached the polygonizer); the helper does not change the mesh.
  const TriangleMesh in = read_mesh(kData + "/hand.off");
  SurfaceMesh mesh[2];
  std::size_t ahead[2];
  for (int k = 0; k < 2; ++k) {
    MesherOptions m;
    m.constraint_build.max_constraints = 1500;
    m.threads = k == 0 ? 1 : 2;
    Mesher mesher = Mesher::from_mesh(in.V, in.F, m);
    REQUIRE(mesher.refine(0.02 * mesher.diagonal()));
    mesh[k] = mesher.surface();
    ahead[k] = mesher.stats().polygonizer.ahead_evaluations;
  }
  CHECK(ahead[0] == 0);
  CHECK(ahead[1] > 0);
  REQUIRE(mesh[0].triangles == mesh[1].triangles);
  REQUIRE(mesh[0].vertices == mesh[1].vertices);
}

// Elephant (genus 3) needs ~1500 surface points (4500 constraints): with fewer, the fitted surface itself
// grows extra handles, so a cheaper model would no longer test genus 3 (only whether subsampling broke
// it). The O(N^3) fit takes ~100 s under the sanitizers (about 5 s in Release), so the case is hidden from
// the `mesher` test and runs as its own CTest entry `mesher_slow` (`test_mesher "[slow]"`, label `slow`,
// tests/mesher/CMakeLists.txt): started first by ctest -j, it overlaps the rest of the suite and
// tools/test.sh still runs every model the issue names. `ctest -LE slow` skips it.
TEST_CASE("real model elephant: genus 3 (Euler characteristic -4)", "[.][slow][mesher]") {
  check_model(ModelCase{"elephant.off", 4500, 0.02, -4});
}

TEST_CASE("levels of detail: more vertices at each level, each watertight", "[mesher]") {
  const TriangleMesh in = read_mesh(kData + "/knot1.off");
  MesherOptions o;
  o.constraint_build.max_constraints = 1500;
  Mesher mesher = Mesher::from_mesh(in.V, in.F, o);
  std::size_t last = 0;
  for (const double p : {0.06, 0.04, 0.03}) {
    REQUIRE(mesher.refine(p * mesher.diagonal()));
    const SurfaceMesh& m = mesher.surface();
    require_closed(m);
    REQUIRE(metrics_of(m).euler_characteristic == 0);
    REQUIRE(m.vertices.size() > last);
    last = m.vertices.size();
  }
}

TEST_CASE("certified mode: levels of a global RBF certified, with the surface's topology", "[mesher][certificate]") {
  // The studio's default model: 24 constraints on a lumpy sphere around one inside constraint, the
  // global function (the one whose enclosures reach second order, docs/certificate.md). At 0.05 and 0.02
  // of the diagonal every tetrahedron is shown empty or crossed by one disk (the faces almost on the
  // surface settled by the curvature, the far terms by their expansion): certified, and the mesh is a
  // sphere. The finer level checks only what changed.
  Constraints c;
  c.add({0, 0, 0}, -1.0);
  for (int i = 0; i < 24; ++i) {
    const double z = 1 - (2 * i + 1) / 24.0, r = std::sqrt(1 - z * z), a = 2.399963 * i;
    const double s = 1 + 0.15 * std::sin(3 * a) * r;
    c.add({s * r * std::cos(a), s * r * std::sin(a), 0.8 * s * z}, 0.0);
  }
  MesherOptions o;
  o.function = FunctionKind::Global;
  o.polygonizer.certify = true;
  Mesher mesher(c, o);
  for (const double p : {0.05, 0.02}) {
    REQUIRE(mesher.refine(p * mesher.diagonal()));
    const PolygonizerStats& s = mesher.stats().polygonizer;
    INFO("precision " << p << ": " << s.uncertified << " uncertified (largest r " << s.uncertified_radius << "), "
                      << s.certify_checked << " checked, " << s.certify_kept << " kept, " << s.certify_insertions
                      << " points");
    REQUIRE(s.uncertified == 0);
    REQUIRE(s.certify_checked > 0);
    if (p < 0.05) REQUIRE(s.certify_kept > 0);
    const SurfaceMesh& m = mesher.surface();
    require_closed(m);
    const MeshMetrics mm = metrics_of(m);
    REQUIRE(mm.components == 1);
    REQUIRE(mm.euler_characteristic == 2);
  }
}

namespace {
Point3 in_point(const TriangleMesh& m, int row) { return {m.V(row, 0), m.V(row, 1), m.V(row, 2)}; }
}  // namespace

TEST_CASE("restarted_copy: the same function and constraints, a fresh polygonization", "[mesher]") {
  const TriangleMesh in = read_mesh(kData + "/knot1.off");
  MesherOptions o;
  o.constraint_build.max_constraints = 600;
  Mesher mesher = Mesher::from_mesh(in.V, in.F, o);
  mesher.refine(0.06 * mesher.diagonal());
  const SurfaceMesh first = mesher.surface();
  mesher.refine(0.04 * mesher.diagonal());  // the original goes on; the copy starts from no level
  Mesher copy = mesher.restarted_copy();
  CHECK(std::isinf(copy.precision()));
  REQUIRE(copy.size() == mesher.size());
  CHECK(copy.constraints().points == mesher.constraints().points);
  CHECK(copy.constraints().values == mesher.constraints().values);
  for (const Point3& q : {Point3{0.1, 0.2, 0.3}, Point3{0.9, -0.4, 0.2}, in_point(in, 7)})
    CHECK(copy.function().value(q) == mesher.function().value(q));
  // The same steps from the same start: the same mesh, vertex for vertex.
  copy.refine(0.06 * copy.diagonal());
  CHECK(copy.surface().vertices == first.vertices);
  CHECK(copy.surface().triangles == first.triangles);
  // Edits on the copy leave the original alone.
  const double before = mesher.function().value(in_point(in, 7));
  copy.move_constraint(0, copy.constraints().points[0] + Point3{0.01, 0, 0});
  CHECK(mesher.function().value(in_point(in, 7)) == before);
  // The local function is not copied.
  MesherOptions local = o;
  local.function = FunctionKind::Local;
  const Mesher l = Mesher::from_mesh(in.V, in.F, local);
  CHECK_THROWS_AS(l.restarted_copy(), InvalidArgument);
}

TEST_CASE("one-call mesh_points equals the stateful mesher", "[mesher]") {
  const Constraints c = small_model();
  Eigen::MatrixXd V, N;
  Eigen::MatrixXi F;
  mesh_points(c, 0.05, V, F, N);
  Mesher m(c);
  m.refine(0.05);
  REQUIRE(V.rows() == static_cast<Eigen::Index>(m.surface().vertices.size()));
  REQUIRE(F.rows() == static_cast<Eigen::Index>(m.surface().triangles.size()));
  REQUIRE(N.rows() == V.rows());
  const MeshMetrics mm = compute_mesh_metrics(V, F);
  REQUIRE(mm.closed_manifold());
  REQUIRE(mm.euler_characteristic == 2);
}

TEST_CASE("unoriented points: from_points and mesh_points estimate and orient the normals", "[mesher][normals]") {
  // The knot's vertices without their faces: the same closed genus-1 surface as from the mesh itself.
  const TriangleMesh in = read_mesh(kData + "/knot1.off");
  std::vector<Point3> p;
  for (Eigen::Index i = 0; i < in.V.rows(); ++i) p.push_back({in.V(i, 0), in.V(i, 1), in.V(i, 2)});
  MesherOptions o;
  o.constraint_build.max_constraints = 1500;
  Mesher mesher = Mesher::from_points(p, o);
  REQUIRE(mesher.size() == 1500);
  REQUIRE(mesher.refine(0.03 * mesher.diagonal()));
  require_closed(mesher.surface());
  REQUIRE(metrics_of(mesher.surface()).euler_characteristic == 0);
  const SurfaceMesh once = mesh_points(p, 0.03 * mesher.diagonal(), o);
  REQUIRE(once.vertices.size() == mesher.surface().vertices.size());
  p.resize(5);
  REQUIRE_THROWS_AS(Mesher::from_points(p, o), InvalidArgument);
}

TEST_CASE("scripted edits: watertight, on the edited surface, close to a fresh mesh", "[mesher]") {
  const double precision = 0.05;
  Mesher mesher(small_model());
  REQUIRE(mesher.refine(precision));
  require_closed(mesher.surface());
  auto check = [&](const char* what) {
    INFO(what);
    const SurfaceMesh& m = mesher.surface();
    require_closed(m);
    REQUIRE(max_surface_distance(m, mesher.function()) <= 0.1 * precision);
    for (const TetId t : mesher.polygonizer().transverse_tetrahedra())
      REQUIRE(mesher.polygonizer().triangulation().circumradius(t) <= precision);
    Mesher fresh(mesher.constraints());
    fresh.refine(precision);
    REQUIRE(hausdorff_distance(m, fresh.surface()) <= precision);
  };
  mesher.move_constraint(3, {1.2, 0.2, 0.1});
  check("move");
  mesher.add_constraint({0.0, 0.0, 0.9}, 0.0);
  check("add");
  mesher.set_value(0, -0.8);
  check("value");
  mesher.remove_constraint(7);
  check("remove");
  REQUIRE(mesher.size() == 25);
  mesher.polygonizer().triangulation().verify_topology();
}

TEST_CASE("100 random edits: vertex count stays within 1.5x of a fresh mesh", "[mesher]") {
  const double precision = 0.06;
  Mesher mesher(small_model());
  REQUIRE(mesher.refine(precision));
  std::mt19937 rng(12345);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int e = 0; e < 100; ++e) {
    const std::size_t n = mesher.size();
    const int kind = static_cast<int>(rng() % 4);
    // A random surface constraint (|value| < 0.5; index 0 is the center, the +1 points are outside).
    std::size_t i = 0;
    do i = 1 + rng() % (n - 1);
    while (std::abs(mesher.constraints().values[i]) >= 0.5);
    const ConstraintId id = mesher.constraint_ids()[i];  // constraint i of constraints()
    if (kind == 0 || n <= 20) {  // move it a little
      const Point3 p = mesher.constraints().points[i];
      mesher.move_constraint(id, {p.x + 0.1 * u(rng), p.y + 0.1 * u(rng), p.z + 0.1 * u(rng)});
    } else if (kind == 1 && n < 30) {  // add a surface point of the ellipsoid
      const Point3 d{u(rng), u(rng), u(rng)};
      const double len = norm(d) + 1e-3;
      mesher.add_constraint({d.x / len, 0.8 * d.y / len, 0.6 * d.z / len}, 0.0);
    } else if (kind == 2 && n > 20) {
      mesher.remove_constraint(id);
    } else {  // nudge its value
      mesher.set_value(id, 0.02 * u(rng));
    }
  }
  const SurfaceMesh& m = mesher.surface();
  require_closed(m);
  Mesher fresh(mesher.constraints());
  fresh.refine(precision);
  INFO("edited: " << mesher.stats().polygonizer.vertices << " Delaunay vertices, fresh: "
                  << fresh.stats().polygonizer.vertices);
  REQUIRE(static_cast<double>(mesher.stats().polygonizer.vertices) <=
          1.5 * static_cast<double>(fresh.stats().polygonizer.vertices));
  REQUIRE(hausdorff_distance(m, fresh.surface()) <= precision);
  mesher.polygonizer().triangulation().verify_topology();
}

// The Mesher keeps the Delaunay vertex of each constraint by its id (a table, O(1) per edit; ids are never
// reused). After many add/remove cycles, every constraint still owns the Delaunay vertex at its point,
// and moving constraint `id` moves that vertex.
TEST_CASE("constraint ids stay tied to their Delaunay vertices over many removals", "[mesher]") {
  Mesher mesher(small_model());  // no refine(): edits skip refinement, so 2500 of them are cheap
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-0.4, 0.4);
  for (int e = 0; e < 1300; ++e) {
    REQUIRE(mesher.add_constraint({u(rng), u(rng), u(rng)}, -0.2) == small_model().size() + std::size_t(e));
    const std::size_t i = 1 + rng() % (mesher.size() - 1);  // anywhere but the center
    mesher.remove_constraint(mesher.constraint_ids()[i]);
  }
  const Triangulation& tri = mesher.polygonizer().triangulation();
  const auto seed_at = [&](const Point3& p) {
    std::size_t count = 0;
    for (VertexId v = 8; v < tri.vertex_capacity(); ++v)
      count += tri.is_vertex(v) && tri.point(v) == p && mesher.polygonizer().vertex_kind(v) == VertexKind::Seed;
    return count;
  };
  REQUIRE(mesher.size() == small_model().size());
  for (std::size_t i = 0; i < mesher.size(); ++i) REQUIRE(seed_at(mesher.constraints().points[i]) == 1);
  const std::vector<ConstraintId> ids = mesher.constraint_ids();
  for (std::size_t i = 0; i < ids.size(); i += 5) {
    const Point3 old = mesher.constraint_point(ids[i]), q = old + Point3{0.01, -0.02, 0.015};
    mesher.move_constraint(ids[i], q);
    REQUIRE(seed_at(q) == 1);
    REQUIRE(seed_at(old) == 0);
  }
  tri.verify_topology();
}

// Stable ids: those of the constraints given are their indices; an add returns the next id; a removal
// changes no other id; an id is never given out again; a removed or unknown id throws UnknownConstraint
// naming it, and changes nothing. Edits by id give the mesh of a fresh Mesher of the same constraints.
TEST_CASE("constraint ids are stable across removals and never reused", "[mesher]") {
  const double precision = 0.08;
  const Constraints c = small_model();  // 25 constraints: ids 0..24
  const FunctionKind kind = GENERATE(FunctionKind::Global, FunctionKind::Local);
  MesherOptions o;
  o.function = kind;
  Mesher mesher(c, o);
  REQUIRE(mesher.refine(precision));
  std::vector<ConstraintId> expected(c.size());
  for (std::size_t i = 0; i < c.size(); ++i) expected[i] = i;
  REQUIRE(mesher.constraint_ids() == expected);

  mesher.remove_constraint(3);
  expected.erase(expected.begin() + 3);
  CHECK(mesher.constraint_ids() == expected);
  // Id 4 still names the same constraint (with shifting indices it would have become index 3).
  CHECK(mesher.constraint_point(4) == c.points[4]);
  CHECK(mesher.constraint_value(4) == c.values[4]);
  const Point3 moved = c.points[4] + Point3{0.05, 0.0, 0.02};
  mesher.move_constraint(4, moved);
  mesher.set_value(10, c.values[10] + 0.05);
  const ConstraintId added = mesher.add_constraint({0.1, 0.1, 0.55}, 0.0);
  CHECK(added == 25);  // the next id: 3 is not given again
  expected.push_back(added);
  CHECK(mesher.constraint_ids() == expected);
  CHECK(mesher.has_constraint(added));
  CHECK_FALSE(mesher.has_constraint(3));
  mesher.remove_constraint(added);
  CHECK(mesher.add_constraint({0.1, 0.1, 0.55}, 0.0) == 26);  // 25 is not given again either
  expected.back() = 26;

  // Unknown ids: a clear error naming the id, nothing changed.
  const std::size_t before = mesher.stats().polygonizer.vertices;
  for (const ConstraintId bad : {ConstraintId{3}, ConstraintId{25}, ConstraintId{27}, ConstraintId{1000}}) {
    INFO("id " << bad);
    try {
      mesher.move_constraint(bad, {0, 0, 0});
      FAIL("no exception");
    } catch (const UnknownConstraint& e) {
      CHECK(e.id() == bad);
      CHECK(e.index() == bad);
      CHECK_THAT(e.what(), Catch::Contains("id " + std::to_string(bad)));
    }
    CHECK_THROWS_AS(mesher.remove_constraint(bad), UnknownConstraint);
    CHECK_THROWS_AS(mesher.set_value(bad, 0.1), InvalidPoint);
    CHECK_THROWS_AS(mesher.constraint_point(bad), UnknownConstraint);
  }
  CHECK(mesher.stats().polygonizer.vertices == before);
  CHECK(mesher.constraint_ids() == expected);

  // constraints() lists the current ones in id order: the same set as a fresh fit's, and the same mesh.
  Constraints now = c;
  now.points[4] = moved;
  now.values[10] += 0.05;
  now.points.erase(now.points.begin() + 3);
  now.values.erase(now.values.begin() + 3);
  now.add({0.1, 0.1, 0.55}, 0.0);
  CHECK(mesher.constraints().points == now.points);
  CHECK(mesher.constraints().values == now.values);
  Mesher fresh(now, o);
  fresh.refine(precision);
  const SurfaceMesh& m = mesher.surface();
  require_closed(m);
  // The edited function is a fresh fit of the current constraints (the local one on the same cube).
  if (kind == FunctionKind::Local) {
    LocalRbfOptions same_cube;
    same_cube.domain = mesher.local_function()->domain();
    const LocalRbf f(now, same_cube);
    for (const Point3& p : m.vertices) CHECK(std::abs(f.value(p) - mesher.function().value(p)) <= 1e-12);
  } else {
    const Rbf f(now);
    for (const Point3& p : m.vertices) CHECK(std::abs(f.value(p) - mesher.function().value(p)) <= 1e-8);
  }
  CHECK(hausdorff_distance(m, fresh.surface()) <= precision);
  // restart() keeps the ids.
  mesher.restart();
  CHECK(mesher.constraint_ids() == expected);
  mesher.polygonizer().triangulation().verify_topology();
}

TEST_CASE("mesher errors", "[mesher]") {
  Mesher mesher(small_model());
  REQUIRE_THROWS_AS(mesher.refine(0.0), InvalidArgument);
  REQUIRE_THROWS_AS(mesher.move_constraint(100, {0, 0, 0}), InvalidPoint);
  REQUIRE_THROWS_AS(mesher.add_constraint({std::nan(""), 0, 0}, 0.0), InvalidPoint);
  // Nothing changed after the failed edits.
  REQUIRE(mesher.size() == 25);
  REQUIRE(mesher.refine(0.1));
  require_closed(mesher.surface());
  MesherOptions o;
  o.box_factor = 1.0;
  REQUIRE_THROWS_AS(Mesher(small_model(), o), InvalidArgument);
}

namespace {

/// Oriented points of a torus (major radius R, tube radius r) on an nu x nv grid, outward normals.
void torus_points(double R, double r, int nu, int nv, std::vector<Point3>& p, std::vector<Point3>& n) {
  const double pi = 3.14159265358979323846;
  for (int i = 0; i < nu; ++i)
    for (int j = 0; j < nv; ++j) {
      const double u = 2 * pi * (i + 0.5 * (j % 2)) / nu, v = 2 * pi * j / nv;
      n.push_back({std::cos(v) * std::cos(u), std::cos(v) * std::sin(u), std::sin(v)});
      p.push_back({(R + r * std::cos(v)) * std::cos(u), (R + r * std::cos(v)) * std::sin(u), r * std::sin(v)});
    }
}

}  // namespace

// Lone zeros (docs/polygonize.md), bug (a): a zero constraint added away from the surface. The RBF
// surface passes through the point and encloses a small region f < 0 next to it, but no vertex is
// negative there: under the plain rule nothing is transverse and the mesh ignores the point.
TEST_CASE("lone zeros: a zero constraint added well outside the surface gets its own surface", "[mesher]") {
  const double precision = 0.05;
  const Point3 p{0.0, 1.2, 0.8};  // the ellipsoid reaches y = 0.8 and z = 0.6; a +1 constraint is at y = 2
  for (const bool lone : {true, false}) {
    INFO("refine_lone_zeros " << lone);
    MesherOptions o;
    o.polygonizer.refine_lone_zeros = lone;
    o.polygonizer.refine_thin_features = lone;  // the thin-feature rule alone can also find it: isolate
    Mesher mesher(small_model(), o);
    REQUIRE(mesher.refine(precision));
    REQUIRE(metrics_of(mesher.surface()).components == 1);
    REQUIRE(MeshDistance(mesher.surface()).distance(p) > 0.3);
    mesher.add_constraint(p, 0.0);
    const SurfaceMesh& m = mesher.surface();
    const double d = MeshDistance(m).distance(p);
    if (lone) {
      require_closed(m);
      REQUIRE(metrics_of(m).components == 2);
      REQUIRE(d <= precision);
      REQUIRE(max_surface_distance(m, mesher.function()) <= 0.1 * precision);
      REQUIRE(mesher.stats().polygonizer.lone_zeros == 0);
      // Kept under edits: moved to the other side, the new surface follows it; removed, it goes away.
      const ConstraintId last = mesher.constraint_ids().back();
      const Point3 q{0.1, -1.2, 0.8};
      mesher.move_constraint(last, q);
      require_closed(mesher.surface());
      REQUIRE(MeshDistance(mesher.surface()).distance(q) <= precision);
      REQUIRE(MeshDistance(mesher.surface()).distance(p) > 0.3);
      mesher.remove_constraint(last);
      require_closed(mesher.surface());
      REQUIRE(metrics_of(mesher.surface()).components == 1);
      REQUIRE(MeshDistance(mesher.surface()).distance(q) > 0.3);
      REQUIRE(mesher.stats().polygonizer.lone_zeros == 0);
      mesher.polygonizer().triangulation().verify_topology();
    } else {
      REQUIRE(d > 0.3);  // the bug this rule fixes
    }
  }
}

// Bug (b): only outside off-surface constraints on a tube thinner than the sampling lattice: no vertex
// is negative at the start, every on-surface constraint is a lone zero.
TEST_CASE("lone zeros: thin torus with outside constraints only is a closed genus-1 mesh", "[mesher]") {
  std::vector<Point3> p, n;
  torus_points(1.0, 0.08, 40, 8, p, n);
  MesherOptions o;
  o.constraint_build.sides = OffSurface::Outside;
  Mesher mesher = Mesher::from_oriented_points(p, n, o);
  REQUIRE(mesher.polygonizer().transverse_tetrahedra().empty());  // precondition: nothing negative
  const double precision = 0.02 * mesher.diagonal();
  REQUIRE(mesher.refine(precision));
  const SurfaceMesh& m = mesher.surface();
  require_closed(m);
  const MeshMetrics mm = metrics_of(m);
  REQUIRE(mm.euler_characteristic == 0);
  REQUIRE(mm.components == 1);
  const MeshDistance md(m);
  for (const Point3& q : p) REQUIRE(md.distance(q) <= precision);

  MesherOptions plain = o;
  plain.polygonizer.refine_lone_zeros = false;
  plain.polygonizer.refine_thin_features = false;  // it would find part of the tube by itself
  Mesher old = Mesher::from_oriented_points(p, n, plain);
  REQUIRE(old.refine(precision));
  REQUIRE(old.surface().triangles.empty());  // the bug this rule fixes
}

// hand.off with one outside constraint per vertex (~2400 constraints, the benchmark's setting of issue 5).
TEST_CASE("lone zeros: hand.off with outside constraints only has the hand's topology", "[mesher]") {
  MesherOptions o;
  o.constraint_build.sides = OffSurface::Outside;
  check_model_with(ModelCase{"hand.off", 0, 0.03, 2}, o);
}

namespace {

/// A closed genus-1 triangle mesh: the torus (major radius R, tube radius r) on an nu x nv grid, each
/// quad split in two, wound counter-clockwise seen from outside.
void torus_mesh(double R, double r, int nu, int nv, Eigen::MatrixXd& V, Eigen::MatrixXi& F) {
  const double pi = 3.14159265358979323846;
  V.resize(nu * nv, 3);
  F.resize(2 * nu * nv, 3);
  for (int i = 0; i < nu; ++i)
    for (int j = 0; j < nv; ++j) {
      const double u = 2 * pi * i / nu, v = 2 * pi * j / nv;
      V.row(i * nv + j) << (R + r * std::cos(v)) * std::cos(u), (R + r * std::cos(v)) * std::sin(u),
          r * std::sin(v);
      const int a = i * nv + j, b = ((i + 1) % nu) * nv + j, c = ((i + 1) % nu) * nv + (j + 1) % nv,
                d = i * nv + (j + 1) % nv;
      F.row(2 * a) << a, b, c;
      F.row(2 * a + 1) << a, c, d;
    }
}

/// Checks a one-call result against the stateful mesher built from the same input: the same mesh
/// (vertex and triangle counts, coordinates), closed, outward, Euler characteristic `euler`, and every
/// on-surface constraint within the precision of it.
void require_same_as_stateful(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F, const Eigen::MatrixXd& N,
                              Mesher& m, double precision, long long euler) {
  const SurfaceMesh& s = m.surface();
  REQUIRE(V.rows() == static_cast<Eigen::Index>(s.vertices.size()));
  REQUIRE(F.rows() == static_cast<Eigen::Index>(s.triangles.size()));
  REQUIRE(N.rows() == V.rows());
  Eigen::MatrixXd V2;
  Eigen::MatrixXi F2;
  to_eigen(s, V2, F2);
  REQUIRE(V == V2);
  REQUIRE(F == F2);
  const MeshMetrics mm = compute_mesh_metrics(V, F);
  REQUIRE(mm.closed_manifold());
  REQUIRE(mm.signed_volume > 0.0);
  REQUIRE(mm.euler_characteristic == euler);
  const MeshDistance md(s);
  const Constraints& cs = m.constraints();
  for (std::size_t i = 0; i < cs.size(); ++i)
    if (cs.values[i] == 0.0) REQUIRE(md.distance(cs.points[i]) <= precision);
}

}  // namespace

TEST_CASE("one-call mesh_points from oriented points: a torus, same as Mesher::from_oriented_points",
          "[mesher]") {
  std::vector<Point3> p, n;
  torus_points(1.0, 0.35, 24, 10, p, n);
  Mesher m = Mesher::from_oriented_points(p, n);
  const double precision = 0.03 * m.diagonal();
  REQUIRE(m.refine(precision));
  Eigen::MatrixXd V, N;
  Eigen::MatrixXi F;
  mesh_points(p, n, precision, V, F, N);
  require_same_as_stateful(V, F, N, m, precision, 0);
  // The SurfaceMesh overload gives the same mesh; the constraint-build options are honoured.
  REQUIRE(mesh_points(p, n, precision).vertices.size() == static_cast<std::size_t>(V.rows()));
  MesherOptions o;
  o.constraint_build.sides = OffSurface::Outside;
  REQUIRE(Mesher::from_oriented_points(p, n, o).size() == 2 * p.size());
  REQUIRE(metrics_of(mesh_points(p, n, precision, o)).euler_characteristic == 0);
  // Errors: one normal missing, a zero normal.
  std::vector<Point3> fewer(n.begin(), n.end() - 1);
  REQUIRE_THROWS_AS(mesh_points(p, fewer, precision), InvalidArgument);
  std::vector<Point3> zero = n;
  zero[5] = {0, 0, 0};
  REQUIRE_THROWS_AS(mesh_points(p, zero, precision), InvalidPoint);
}

TEST_CASE("one-call mesh_points from a closed mesh: a torus mesh, same as Mesher::from_mesh", "[mesher]") {
  Eigen::MatrixXd inV;
  Eigen::MatrixXi inF;
  torus_mesh(1.0, 0.35, 24, 10, inV, inF);
  Mesher m = Mesher::from_mesh(inV, inF);
  REQUIRE(m.size() == 3 * static_cast<std::size_t>(inV.rows()));
  const double precision = 0.03 * m.diagonal();
  REQUIRE(m.refine(precision));
  Eigen::MatrixXd V, N;
  Eigen::MatrixXi F;
  mesh_points(inV, inF, precision, V, F, N);
  require_same_as_stateful(V, F, N, m, precision, 0);
  // Triangles wound inwards give the same surface (normals are flipped to point outwards).
  Eigen::MatrixXi flipped = inF;
  flipped.col(1).swap(flipped.col(2));
  const SurfaceMesh s = mesh_points(inV, flipped, precision);
  REQUIRE(s.vertices.size() == static_cast<std::size_t>(V.rows()));
  REQUIRE(metrics_of(s).signed_volume > 0.0);
  // An open mesh (one triangle dropped) has no inside.
  const Eigen::MatrixXi open = inF.topRows(inF.rows() - 1);
  REQUIRE_THROWS_AS(mesh_points(inV, open, precision, V, F, N), InvalidArgument);
}
