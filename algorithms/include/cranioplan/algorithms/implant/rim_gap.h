#pragma once
// The gap between an implant's edge and the bone it meets, as the quality report judges it and
// as the fit to the bone aims for it: around the implant's axis, over every 5° arc of its side
// wall, the wall vertex nearest the bone; the rim gap is the worst arc's distance.
#include <Eigen/Core>
#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "cranioplan/model/material.h"
#include "cranioplan/model/mesh.h"
#include "cranioplan/model/plane.h"

namespace cranioplan {

class SurfaceLocator;

/// The rim gap automatic plans aim for (mm): a larger one is shown and located (the wizard's
/// view, the report's row), and the fit to the bone tries other margins to close it
/// (ImplantParams::fit_margin_search); over QualityParams::max_rim_gap_mm the implant is not
/// printable.
inline constexpr double kRimGapTargetMm = 0.5;

/// The arcs the rim gap is judged over (radians): 5°.
inline constexpr double kRimArcRad = 3.14159265358979323846 / 36.0;

/// Where on the implant a gap is, as the messages and reports write it: " at (x, y, z) mm" to a
/// tenth of a millimetre (the quality report's reasons and row, the fit's margin note).
std::string at_point_text(const Eigen::Vector3d& p);

/// The rim gap over arcs of the rim: for every arc `arc_rad` wide around the circle (sliding,
/// not fixed sectors), the smallest of `distance[i]` over the points `angle[i]` (radians, any
/// range) inside it; the largest over the arcs that hold a point. 0 without points. It is the
/// same for the points turned by any angle: fixed sectors would start at the mesh's first wall
/// vertex, so the same implant would give other gaps with its vertices listed in another order,
/// and a gap straddling two sectors could hide in both. `where`, when given, receives the index
/// of the point whose distance is the result (the worst arc's nearest point).
double worst_arc_gap(const std::vector<double>& angle, const std::vector<double>& distance,
                     double arc_rad, size_t* where = nullptr);

/// The implant's thinnest principal axis (across the plate) through its vertex centroid `c`.
Eigen::Vector3d plate_axis(const SkullMesh& implant, const Eigen::Vector3d& c);

/// Whether a face with unit normal `n` is one of the plate's two large surfaces (within 45° of
/// `axis`); the others are its side wall.
bool across_plate(const Eigen::Vector3d& n, const Eigen::Vector3d& axis);

/// The side wall's vertices against the bone, each once: its angle around `axis` through `c`,
/// its distance to the bone and the bone point it faces.
struct RimSamples {
  std::vector<int> vertices;
  std::vector<double> angle, distance;
  std::vector<Eigen::Vector3d> nearest;
};
/// A wall vertex this near a plane where the scan ended lies at the scan's end, mm.
inline constexpr double kAtScanEndMm = 1.0;

/// `wall_vertices`: the side wall's vertices (repeats allowed). A vertex within kAtScanEndMm
/// of a plane of `scan_ends` (where the scan ended: the implant ends there, and no bone is
/// known beyond) counts as meeting the bone (distance 0, facing itself).
RimSamples rim_samples(const SkullMesh& implant, const SurfaceLocator& bone,
                       const Eigen::Vector3d& c, const Eigen::Vector3d& axis,
                       std::vector<int> wall_vertices, const std::vector<Plane>& scan_ends = {});

/// Each sample's gap over the clearance asked at the bone it faces (`clearance_mm`, or a
/// zone's); samples with `skip[i]` set count as exactly as asked (0). `skip` may be empty.
std::vector<double> clearance_excess(const RimSamples& s, double clearance_mm,
                                     const std::vector<ClearanceZone>& zones,
                                     const std::vector<bool>& skip = {});

/// The rim gap of an implant against the bone, as the quality report measures it; with a
/// clearance asked (`clearance_asked`), the worst arc's excess over it instead. `at`: the worst
/// arc's wall point (unset for an implant without a side wall).
struct RimGap {
  double mm = 0.0;
  std::optional<Eigen::Vector3d> at;
};
RimGap rim_gap(const SkullMesh& implant, const SurfaceLocator& bone, bool clearance_asked,
               double clearance_mm, const std::vector<ClearanceZone>& zones,
               const std::vector<Plane>& scan_ends = {});

}  // namespace cranioplan
