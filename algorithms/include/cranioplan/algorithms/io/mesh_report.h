#pragma once
#include <Eigen/Core>
#include <string>
#include <vector>

#include "cranioplan/model/mesh.h"

namespace cranioplan {

/// One connected chain of boundary edges (edges with one triangle): a loop around a hole, or
/// loops that touch at a vertex.
struct BoundaryLoop {
  long long edges = 0;
  double length_mm = 0.0;
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();  ///< of its vertices, mm
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();   ///< of the plane that fits it best
  double flatness_mm = 0.0;  ///< the largest distance of its vertices from that plane
  /// Flat, at least 30 mm across, and its plane is where the mesh ends along the normal (within
  /// 2 mm), in any orientation: the cut where a scan ended (a tilted gantry's too), or where an
  /// exporter cropped the surface.
  bool at_border = false;
  /// At the border: the unit normal pointing out of the surface through the cut (an axis when
  /// within 1° of one); zero otherwise.
  Eigen::Vector3d outward = Eigen::Vector3d::Zero();
  /// Which border, in the patient's LPS frame, by the axis nearest `outward`: "lower" (−z),
  /// "upper" (+z), "front" (−y), "back" (+y), "right" (−x), "left" (+x); empty unless at_border.
  std::string border;
  /// At the border: the convex hull of its vertices seen along `outward`, counter-clockwise
  /// about it (hull_in_plane); empty otherwise.
  std::vector<Eigen::Vector3d> outline;
};

/// A flat cap where a closed surface ends: the triangles within 2 mm of the mesh's end along a
/// direction and facing out through it within 30°, at least 200 mm² of them, 60 × 30 mm across
/// or more, and a ring (their convex outline encloses 1,000 mm² or more that they do not cover,
/// and they cover at most half of it). An importer that pads the volume (this program's, 3D
/// Slicer's closed surfaces) leaves one where the scan ended: the bone's cross-section is closed
/// there, and the head's inside is open through it.
struct BorderCap {
  /// Unit normal out of the surface through the cap (an axis when within 1° of one).
  Eigen::Vector3d outward = Eigen::Vector3d::Zero();
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();  ///< of its triangles' area, mm
  double area_mm2 = 0.0;
  Eigen::Vector3d box_min = Eigen::Vector3d::Zero();  ///< of its triangles, mm
  Eigen::Vector3d box_max = Eigen::Vector3d::Zero();
  /// The convex hull of its triangles in its plane, counter-clockwise about `outward`: the
  /// outline of the bone's cross-section, around the head's inside that the cap leaves open.
  std::vector<Eigen::Vector3d> outline;
  std::string border;  ///< which border, named as BoundaryLoop::border
};

struct MeshReport {
  long long vertices = 0;
  long long triangles = 0;
  Eigen::Vector3d bbox_min = Eigen::Vector3d::Zero();  ///< mm
  Eigen::Vector3d bbox_max = Eigen::Vector3d::Zero();  ///< mm
  double area_mm2 = 0.0;
  double volume_mm3 = 0.0;          ///< signed: positive for closed outward-oriented meshes
  long long boundary_edges = 0;     ///< edges with one triangle (after welding equal points)
  long long nonmanifold_edges = 0;  ///< edges with three or more triangles
  long long pieces = 0;             ///< connected pieces
  bool watertight = false;          ///< no boundary and no non-manifold edge
  std::vector<BoundaryLoop> loops;  ///< the boundary's chains, longest first
  std::vector<BorderCap> caps;      ///< flat caps at its border, largest first
};

/// The convex hull of `points` seen along `normal` (as projected on a plane across it),
/// counter-clockwise about `normal`; the points themselves, not their projections. Fewer than
/// three points are returned as they are.
std::vector<Eigen::Vector3d> hull_in_plane(std::vector<Eigen::Vector3d> points,
                                           const Eigen::Vector3d& normal);

/// What a person should know of a skull mesh's openness, one sentence each (empty when it is
/// closed): the flat cuts at its border ("open along a flat cut at its lower border (z = −1.0 mm):
/// 3 loops, 412 mm"), and the other holes with the largest's size and place.
std::vector<std::string> describe_openings(const MeshReport& report);

/// The flat caps at its border, one sentence each, none on a side where it is also open
/// ("closed by a flat cap at its lower border (z = -0.4 mm): 1913 mm², where the scan ended;
/// ..."): what the mesh has, not a repair, so not among a load's warnings (`info` lists them).
std::vector<std::string> describe_caps(const MeshReport& report);

/// Counts and measures a mesh. Vertices at identical positions are treated as one, so edges a
/// reader split to keep OpenMesh manifold are still reported as non-manifold.
MeshReport report_mesh(const SkullMesh& mesh);

/// report_mesh(mesh).caps alone, without welding, edges, loops and pieces: for a closed mesh,
/// where the caps are all of its border there is.
std::vector<BorderCap> border_caps(const SkullMesh& mesh);

/// report_mesh(mesh).watertight alone (the same welding of identical positions), without the
/// loops and pieces: for a flag on every implant built.
bool is_watertight(const SkullMesh& mesh);

}  // namespace cranioplan
