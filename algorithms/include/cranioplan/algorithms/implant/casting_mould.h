#pragma once
// A two-part casting mould for an implant cast in theatre (PMMA bone cement), printed on a
// desktop FDM printer: a block around the implant split along a parting surface through the
// middle of the implant's side wall, its cavity the implant, with hemispherical alignment keys
// on the parting face and a pour channel and an air vent through the outer half.
#include <Eigen/Core>
#include <string>

#include "cranioplan/model/mesh.h"
#include "cranioplan/model/param_spec.h"

namespace cranioplan {

// The fields' ranges, units and meanings are declared in for_each_field below.
struct MouldParams {
  double wall_mm = 8.0;
  double key_diameter_mm = 5.0;
  double key_clearance_mm = 0.2;
  double channel_diameter_mm = 5.0;
  double vent_diameter_mm = 2.0;
  double voxel_mm = 0.2;
  double max_voxels = 3e7;  ///< a large mould's grid is coarsened to this many voxels
  /// Field values within 1e-3 of the meshing's iso-level are moved that far off it (no sliver
  /// triangles); false: only a value exactly at it, as plans saved before this were meshed (set
  /// from the session command's version, not recorded).
  bool iso_gap = true;
};
/// MouldParams' fields, each declared once (ParamSpec), in the order a session writes them.
template <class Visit>
void for_each_field(Visit&& visit, MouldParams& p) {
  visit(length_mm("wall_mm", "wall", 4, 30).with_option("wall", "the block beyond the cavity"),
        p.wall_mm);
  visit(length_mm("key_diameter_mm", "keys' diameter", 2, 12)
            .with_option("key-diameter", "the alignment keys' hemispheres"),
        p.key_diameter_mm);
  visit(length_mm("key_clearance_mm", "keys' clearance", 0, 1)
            .with_option("key-clearance", "sockets wider than the keys by this"),
        p.key_clearance_mm);
  visit(length_mm("channel_diameter_mm", "pour channel's diameter", 2, 12)
            .with_option("channel-diameter", "the pour channel"),
        p.channel_diameter_mm);
  visit(length_mm("vent_diameter_mm", "vent's diameter", 1, 6)
            .with_option("vent-diameter", "the air vent"),
        p.vent_diameter_mm);
  visit(length_mm("voxel_mm", "grid", 0.05, 1), p.voxel_mm);
  visit(number("max_voxels", "number of grid voxels", 1e5, 1e8), p.max_voxels);
}
/// Why the parameters cannot be used (a value out of its range), or empty.
std::string mould_problem(const MouldParams& p);

struct MouldResult {
  enum class Status { Made, Failed };
  Status status = Status::Failed;
  std::string message;
  SkullMesh outer, inner;  ///< the halves: the one over the implant's outer surface, the other
  /// The halves part along it (outer: +): of the implant's thinnest principal axis and the
  /// directions 10° and 20° around it, the one that traps the least of the implant.
  Eigen::Vector3d axis = Eigen::Vector3d::UnitZ();
  Eigen::Vector3d pour = Eigen::Vector3d::Zero(), vent = Eigen::Vector3d::Zero();  ///< openings
  /// How far the cavity's surface lies from the implant's: over the implant's vertices (away
  /// from the channel and vent), the distance to the nearer half, mm: the largest and the 95th
  /// percentile.
  double cavity_max_mm = 0.0, cavity_p95_mm = 0.0;
  double cavity_beyond_0_2 = 0.0;  ///< the share of those vertices farther than 0.2 mm (0..1)
  /// The largest over the vertices outside the folds (`trapped_mm2`): where a line along the
  /// pull crosses the implant only twice, mm.
  double cavity_free_max_mm = 0.0;
  /// The implant's surface that a half would trap (its normal turns more than 2° against the
  /// half's pull), mm²: 0 for a mould that opens.
  double undercut_mm2 = 0.0;
  /// Of that, the area where a line along the pull crosses the implant four or more times: the
  /// implant folds back over itself along the pull there, so no parting surface frees it (a
  /// bulging side wall, a lip); the rest is the parting's 0.5 mm sampling at steep walls, mm².
  double trapped_mm2 = 0.0;
  double seconds = 0.0;
  bool usable() const { return status == Status::Made; }
};
/// "made" or "failed".
const char* status_name(MouldResult::Status status);

/// The mould of `implant` (closed, outward-oriented); `inside`: a point inside the skull, which
/// tells the implant's outer surface from its inner one.
MouldResult make_casting_mould(const SkullMesh& implant, const Eigen::Vector3d& inside,
                               const MouldParams& params = {});

}  // namespace cranioplan
