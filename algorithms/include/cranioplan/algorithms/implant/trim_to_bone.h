#pragma once
// Fits an implant to the skull it is made for: the bone is subtracted from the implant on a fine
// voxel grid, slivers left on top of intact bone are removed, and the rest is meshed again with
// a smooth surface. An implant built a little larger than the opening thereby meets the cut face
// of the defect everywhere (no gap) and never enters the bone (no overlap).
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "cranioplan/model/material.h"
#include "cranioplan/model/mesh.h"
#include "cranioplan/model/plane.h"

namespace cranioplan {

struct TrimToBoneParams {
  double voxel_mm = 0.25;  ///< grid of the subtraction, mm (0.1..1)
  /// A large implant gets a coarser grid so that it has no more voxels than this (memory and
  /// time grow with the count; 6 million is about 0.45 mm over a 110 × 90 × 60 mm implant).
  double max_voxels = 6e6;
  /// Parts thinner than this (slivers on the bone, filaments between bone fragments) go, mm
  /// (≥ 0). Half a millimetre above the quality report's 1 mm minimum: the surface is then
  /// blurred (and, without a clearance, kept a voxel off the bone), which thins what is left:
  /// a smaller width keeps edges under 1 mm between crushed bone fragments (docs/IMPLANT.md;
  /// docs/decisions/0005-the-trim.md).
  double min_feature_mm = 1.5;
  double smoothing_mm = 0.3;  ///< Gaussian blur of the mask before meshing (σ), mm (≥ 0)
  /// Cracks narrower than twice this between the implant and the bone (the implant on one side,
  /// the bone on the other, along one of 13 directions) are filled, mm (0: off). Ragged bone
  /// (crushed fragments by an orbit) leaves cracks up to 3 mm wide along the implant's edge.
  double bridge_mm = 1.5;
  /// Where a fill leaves material thinner than min_feature_mm more than 1 mm from the bone (a
  /// rod between the implant's edge and a fragment, rather than a wall against a cut face), it
  /// goes. False: fills are kept as made (build_implant commands before version 4).
  bool thin_fills_removed = true;
  /// The implant's surface keeps this far off the skull's surface where it meets it, mm (≥ 0),
  /// to a fraction of the grid (from the distance to the skull's triangles). Unset: the bone's
  /// voxels grown by one voxel are kept out (build_implant commands before version 4); the
  /// surface then lies
  /// 0.5-1.5 voxels off the bone (up to 0.7 mm on a large implant's 0.45 mm grid), which left
  /// a layer of the defect unfilled along its cut face.
  std::optional<double> clearance_mm = 0.1;
  /// Stretches of the edge held further off (the largest of `clearance_mm` and the zones that
  /// hold a point applies there); used only with a clearance set.
  std::vector<ClearanceZone> zones;
  /// The skull's inside where its surface is open (the cut where the scan ends): decided by
  /// parity-count voting along three axes (VoxelizeParams::vote_through_holes). false: parity
  /// along z, as plans saved before version 0.2 fitted their implants (a skull open at the
  /// scan's lower border then counted the air above its cut as bone, and the bone as air).
  bool vote_through_holes = true;
  /// The smooth field kept 1e-3 off its iso-level before meshing (keep_off_iso_level): no
  /// triangles without area, whose neighbours seem to cross. false: meshed as it comes
  /// (build_implant commands before version 11).
  bool iso_gap = true;
  /// Where the scan ended (ImplantParams::scan_ends): what lies beyond these planes (on their
  /// normals' side) is cut away.
  std::vector<Plane> scan_ends;
};

struct TrimToBoneResult {
  enum class Status { Trimmed, Empty };
  Status status = Status::Empty;
  std::string message;
  SkullMesh mesh;            ///< closed, outward-oriented (the input, untouched, when Empty)
  double removed_mm3 = 0.0;  ///< volume taken away (bone overlap and slivers)
  double volume_mm3 = 0.0;   ///< volume kept
  double seconds = 0.0;
  /// Where the time went, stage by stage in the order they ran (bench's profile of the fit), s.
  std::vector<std::pair<std::string, double>> stage_seconds;
  bool usable() const { return status == Status::Trimmed; }
};

/// `implant` and `skull` must be closed surfaces (the skull's bone as a solid). The result
/// keeps `clearance_mm` off the skull's surface (unset: a fraction of a voxel off its voxels).
TrimToBoneResult trim_to_bone(const SkullMesh& implant, const SkullMesh& skull,
                              const TrimToBoneParams& params = {});
class SurfaceLocator;
/// The same with the result meshed in `into` (whatever it held is replaced; the result's own
/// mesh stays empty): a mesh cannot be moved, only copied. `into` must not be `implant`.
/// `skull_locator`: the skull's locator, when the caller has one (the same result, without
/// a locator of the skull's triangles near the implant built for the fit).
TrimToBoneResult trim_to_bone(const SkullMesh& implant, const SkullMesh& skull,
                              const TrimToBoneParams& params, SkullMesh& into,
                              const SurfaceLocator* skull_locator = nullptr);

}  // namespace cranioplan
