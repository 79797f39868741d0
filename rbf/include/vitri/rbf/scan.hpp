#pragma once
/// @file scan.hpp
/// Scanned points as sensors deliver them (noise, outliers, uneven density, no or unreliable normals,
/// single views) turned into oriented points that the normal constraints of constraints.hpp can
/// interpolate: prepare_scan(). What it measures (spacing, noise, outliers) and what it decided (the
/// neighbourhood size, where the orientation came from) is returned in a ScanReport. Method, estimators
/// and limits: docs/scans.md.
///
///   vitri::ScanReport report;
///   vitri::ScanPoints s = vitri::prepare_scan(points, {}, {}, &report);   // no normals, no viewpoint
///   vitri::Constraints c = vitri::constraints_from_oriented_points(s.points, s.normals);

#include "vitri/core/point.hpp"

#include <cstddef>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace vitri {

/// Options of prepare_scan().
struct ScanOptions {
  /// Neighbours per point for the noise estimate, the tangent planes and the projection; 0 (default):
  /// chosen from the data, 16 to 96, larger where the noise is large against the neighbourhood (the
  /// neighbourhood must be several times wider than the noise to see a surface). At least 6 otherwise.
  std::size_t k = 0;
  /// Approximate instead of interpolate: every point is moved onto the weighted least-squares quadric
  /// of its neighbourhood (a moving-least-squares projection), by at most the neighbourhood's own
  /// residual scale. false keeps the points where they are (the interpolating mode).
  bool approximate = true;
  /// Points far from the surface their neighbours agree on, or in a density far below their
  /// neighbours', or in a small cluster cut off from the rest, are set aside (no constraint); counted in
  /// ScanReport::outliers. false keeps every point.
  bool remove_outliers = true;
  /// The sensor's position for the whole cloud (a single view): every normal is oriented toward it,
  /// unless the data contradict it (ScanReport::viewpoint_rejected).
  std::optional<Point3> viewpoint;
  /// One sensor position per point (empty, or one per point): each normal is oriented toward its own.
  std::vector<Point3> sensors;
  /// Depth quantization undone (with a viewpoint and `approximate` only; docs/scans.md, step 1b): when
  /// one measure of the points seen from the viewpoint (its x, y or z offset, or the range) takes at most
  /// n / 100 distinct values and at least 10x fewer than the others (structured-light and stereo
  /// cameras store depth in discrete steps), each point moves along its ray within its own step, to the
  /// depth interpolated between the edges of its step's band and averaged with its neighbours in the
  /// image (ScanReport::dequantized). The points stay within half a step of where they were given.
  bool dequantize = true;
  /// Threads (0: every available CPU). The result does not depend on it.
  unsigned threads = 0;
};

/// Where the signs of the normals came from.
enum class OrientationSource {
  Given,      ///< the input's normals (checked against their neighbourhood, see ScanReport::repaired)
  Viewpoint,  ///< toward ScanOptions::viewpoint
  Sensors,    ///< toward each point's ScanOptions::sensors entry
  Estimated,  ///< a minimum spanning tree of the neighbour graph (orient_normals, never refusing)
};

/// What prepare_scan() measured and decided.
struct ScanReport {
  std::size_t input = 0;       ///< points given
  std::size_t duplicates = 0;  ///< exact duplicate positions dropped (the first copy kept)
  std::size_t outliers = 0;    ///< points set aside as outliers (ScanOptions::remove_outliers)
  std::size_t kept = 0;        ///< points returned
  /// Points left out after the projection because a kept one lay within half the resolution (only
  /// where the resolution exceeds 1.5 spacings: noise larger than the spacing; ScanOptions::approximate).
  std::size_t thinned = 0;
  /// Points moved to the middle of two misregistered layers (sheets of one orientation a few spacings
  /// apart: docs/scans.md) before the projection.
  std::size_t merged = 0;
  /// Points whose projection fitted a wider neighbourhood than k: their region's noise asked for more
  /// (docs/scans.md, step 7).
  std::size_t widened = 0;
  /// Depth quantization found (ScanOptions::dequantize): the measure ("x", "y", "z": the offset from
  /// the viewpoint along that axis, or "range"), its distinct values (levels), the smallest and largest
  /// step between neighbouring levels, and the points moved within their step (empty measure: none).
  std::string quantized;
  std::size_t levels = 0;
  double step_min = 0, step_max = 0;
  std::size_t dequantized = 0;
  std::size_t k = 0;           ///< neighbours per point used
  /// The median distance from a returned point to its nearest other one.
  double spacing = 0;
  /// The median over the points of the RMS distance of their neighbourhood to its least-squares quadric
  /// (before the projection): the noise of the data, curvature excluded (sharp edges count as noise).
  double noise = 0;
  /// The finest detail the data resolve: max(spacing, 2 x noise).
  double resolution = 0;
  /// The median distance a point was moved by the projection (0 when not approximating).
  double moved = 0;
  OrientationSource orientation = OrientationSource::Estimated;
  /// Given normals that disagreed with their neighbourhood: more than 60 degrees off its tangent plane's
  /// normal (replaced by it), or pointing against the neighbours (flipped).
  std::size_t repaired = 0;
  /// Points whose sign stayed a guess: reached across a weak link or in a small or unseeded component
  /// (OrientationReport::ambiguous), seen edge-on from the viewpoint, or decided by a vote of neighbours.
  std::size_t ambiguous = 0;
  /// Points of regions whose sign the spanning tree had set across a sharp edge, flipped so that the
  /// winding number of the whole is that of a closed surface (docs/scans.md, step 4: a cone's base).
  std::size_t regions_flipped = 0;
  /// Points on sharp edges (their neighbourhood's fit straddling two faces) given the normal of the
  /// smooth neighbour on whose tangent plane they lie (estimated normals only).
  std::size_t edge_normals = 0;
  /// The viewpoint or sensors were given but contradicted by the data (the orientation then was
  /// estimated); viewpoint_note says why.
  bool viewpoint_rejected = false;
  std::string viewpoint_note;
  /// The points of the sample whose own orientation decided that a viewpoint outside the data's box is
  /// accepted (docs/scans.md, step 4); 0 when every point's did (fewer than 40,000 points, a share near
  /// the limit, or the viewpoint rejected).
  std::size_t viewpoint_sample = 0;
  double seconds = 0;  ///< wall time of prepare_scan()
  /// Where that time went, step by step in the order run (name, wall seconds): "duplicates",
  /// "dequantize", "neighbours" (the lists, the fits, the choice of k), "outliers" (every round),
  /// "orientation", "layers" (misregistered layers merged), "projection", "thinning". A step that did
  /// not run is absent.
  std::vector<std::pair<std::string, double>> steps;
};

/// Oriented points ready for constraints_from_oriented_points(), with what the mesher needs to follow
/// the data: `spacing[i]` the local spacing around point i (the side of the area per point in its
/// neighbourhood).
struct ScanPoints {
  std::vector<Point3> points;
  std::vector<Point3> normals;  ///< unit, oriented outward (toward the sensor for a single view)
  std::vector<double> spacing;
  /// The points set aside as outliers, where they were given: what the mesher's component rule weighs
  /// against the kept points (a component grown among set-aside points is a blob of outliers).
  std::vector<Point3> set_aside;
};

/// Prepares scanned points for the normal constraints: exact duplicates dropped, outliers set aside,
/// noise measured and (ScanOptions::approximate) absorbed by a local quadric projection, unit normals
/// from the projection's tangent plane, oriented from `normals` (one per point, any length; empty when
/// the scan has none), the viewpoint or sensors, or estimated. Nothing is refused for the data's defects.
/// @throws InvalidPoint (index) for a non-finite coordinate or normal; InvalidArgument when `normals` or
///         options.sensors has a size other than 0 or points.size(), when fewer than 8 distinct points
///         remain ("no surface"), or when every point lies on one line.
ScanPoints prepare_scan(const std::vector<Point3>& points, const std::vector<Point3>& normals = {},
                        const ScanOptions& options = {}, ScanReport* report = nullptr);

/// ScanReport as one line for people ("12 outliers set aside, noise 0.31 spacings, ...").
std::string describe(const ScanReport& report);

}  // namespace vitri
