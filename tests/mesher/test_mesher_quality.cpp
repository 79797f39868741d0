// Tests of the Mesher's quality mode on a real model through the RBF (data/hand.off): the guarantees of
// docs/quality.md over all triangles, at two levels of detail and after dynamic edits.
#include <catch2/catch.hpp>

#include "support/quality_checks.hpp"
#include "vitri/core/error.hpp"
#include "vitri/io/io.hpp"
#include "vitri/mesher.hpp"

#include <string>

using namespace vitri;

namespace {

const std::string kData = VITRI_DATA_DIR;

/// hand.off, subsampled to 1500 surface points (as the fast-mode model tests), in the quality mode with
/// a distance bound relative to the diagonal.
Mesher hand_in_quality_mode(double angle, double relative_distance) {
  const TriangleMesh in = read_mesh(kData + "/hand.off");
  MesherOptions o;
  o.constraint_build.max_constraints = 1500;
  o.mode = MeshMode::Quality;
  o.quality.min_angle_degrees = angle;
  Mesher mesher = Mesher::from_mesh(in.V, in.F, o);
  QualityOptions q = mesher.options().quality;
  q.max_distance = relative_distance * mesher.diagonal();
  mesher.set_quality_options(q);
  return mesher;
}

}  // namespace

TEST_CASE("quality mode on hand.off: angles, closed outward genus 0, distance, levels of detail",
          "[mesher]") {
  Mesher mesher = hand_in_quality_mode(30.0, 0.002);
  const double diag = mesher.diagonal();
  REQUIRE(mesher.refine(0.03 * diag));
  REQUIRE(mesher.quality_mesher() != nullptr);
  const SurfaceMesh coarse = mesher.surface();
  test::require_quality(coarse, mesher.function(), mesher.options().quality, 2, 1, 1.25, 1e-7 * diag);
  // A finer distance bound continues the same quality structure.
  QualityOptions q = mesher.options().quality;
  q.max_distance = 0.001 * diag;
  mesher.set_quality_options(q);
  REQUIRE(mesher.refine(0.03 * diag));
  const SurfaceMesh fine = mesher.surface();
  test::require_quality(fine, mesher.function(), q, 2, 1, 1.25, 1e-7 * diag);
  REQUIRE(fine.vertices.size() > coarse.vertices.size());
  REQUIRE(mesher.stats().quality.insertions > 0);
}

TEST_CASE("quality mode on hand.off: the same guarantees after edits", "[mesher]") {
  Mesher mesher = hand_in_quality_mode(30.0, 0.002);
  const double diag = mesher.diagonal();
  REQUIRE(mesher.refine(0.03 * diag));
  // Move a surface constraint outwards along the first axis, then remove another one.
  const Point3 p = mesher.constraints().points[10];
  // After an edit the vertices are on the new surface to the edit tolerance (of the domain diagonal).
  const double edited = 1.001 * mesher.options().quality.edit_tolerance *
                        mesher.quality_mesher()->triangulation().box().diagonal();
  mesher.move_constraint(10, p + Point3{0.02 * diag, 0.0, 0.0});
  test::require_quality(mesher.surface(), mesher.function(), mesher.options().quality, 2, 1, 1.25, edited);
  CHECK(mesher.stats().quality.projected > 0);
  mesher.remove_constraint(200);
  test::require_quality(mesher.surface(), mesher.function(), mesher.options().quality, 2, 1, 1.25, edited);
}

TEST_CASE("quality mode: bad quality options are rejected before the fit", "[mesher]") {
  MesherOptions o;
  o.mode = MeshMode::Quality;
  o.quality.min_angle_degrees = 45.0;
  Constraints c;
  c.add({0.0, 0.0, 0.0}, -1.0);
  c.add({1.0, 0.0, 0.0}, 0.0);
  REQUIRE_THROWS_AS(Mesher(c, o), InvalidArgument);
}

TEST_CASE("quality mode with the local function: guarantees before and after an edit", "[mesher][local]") {
  // Every vertex of knot1 (9600 constraints): the partition-of-unity function.
  const TriangleMesh in = read_mesh(kData + "/knot1.off");
  MesherOptions o;
  o.function = FunctionKind::Local;
  o.mode = MeshMode::Quality;
  Mesher mesher = Mesher::from_mesh(in.V, in.F, o);
  REQUIRE(mesher.local_function() != nullptr);
  const double diag = mesher.diagonal();
  QualityOptions q = mesher.options().quality;
  q.max_distance = 0.003 * diag;
  mesher.set_quality_options(q);
  REQUIRE(mesher.refine(0.03 * diag));
  test::require_quality(mesher.surface(), mesher.function(), q, 0, 1, 1.25, 1e-7 * diag);
  const double edited =
      1.001 * q.edit_tolerance * mesher.quality_mesher()->triangulation().box().diagonal();
  const Point3 p = mesher.constraints().points[100];
  mesher.move_constraint(100, p + Point3{0.005 * diag, 0.0, 0.0});
  test::require_quality(mesher.surface(), mesher.function(), q, 0, 1, 1.25, edited);
}
