#pragma once
// Known answers on real skulls: cut a defect out of a healthy skull, keeping what was removed
// as the ground-truth implant (as the AutoImplant / SkullBreak data sets were made).
#include <optional>
#include <string>

#include "cranioplan/model/mesh.h"
#include "cranioplan/model/plane.h"

namespace cranioplan {

/// A bone flap as a surgeon saws it: the bone inside an elliptical cone from a point inside the
/// cranial cavity (`apex`), so the cut faces run through the bone's thickness as a craniotome
/// cuts them, not along the rays of the cone's axis alone. The ellipse is measured by angles
/// from `axis`: a point belongs to the flap when (α/half_length)² + (β/half_width)² ≤ 1, where α
/// and β are its angles from the axis towards `along` and towards axis × along. Bone nearer the
/// midsagittal plane than `midline_margin_mm` (a strip kept over the sagittal sinus) is kept;
/// with `one_side` only bone on that side of the plane is cut. Bone below `floor` (its negative
/// side: the floor of the cranial fossae, which a craniectomy reaches but does not cross) is kept.
struct FlapCut {
  Eigen::Vector3d apex = Eigen::Vector3d::Zero();    ///< inside the cavity, mm
  Eigen::Vector3d axis = Eigen::Vector3d::UnitX();   ///< unit, towards the flap's centre
  Eigen::Vector3d along = Eigen::Vector3d::UnitY();  ///< unit, across the axis: the long direction
  double half_length_rad = 0.8;                      ///< angular half-length along `along`
  double half_width_rad = 0.6;                       ///< angular half-width across it
  std::optional<Plane> midline;                      ///< the midsagittal plane
  double midline_margin_mm = 0.0;                    ///< bone this near the plane is kept, mm
  /// Cut only where midline->signed_distance has this sign (+1 or −1); 0: either side.
  int one_side = 0;
  std::optional<Plane> floor;  ///< bone on its negative side is kept
  /// The point lies in the flap.
  bool contains(const Eigen::Vector3d& x) const;
};

struct InjectDefectParams {
  enum class Shape { Sphere, Cube, Flap };
  Shape shape = Shape::Sphere;
  Eigen::Vector3d center = Eigen::Vector3d::Zero();  ///< mm (sphere and cube)
  double size_mm = 40.0;                             ///< sphere diameter or cube edge, mm (>0)
  FlapCut flap;                                      ///< Shape::Flap
  double voxel_mm = 0.4;                             ///< resolution of the cut, mm (0.1..2)
};

struct InjectDefectResult {
  enum class Status { Injected, NoBoneInDefect };
  Status status = Status::NoBoneInDefect;
  std::string message;
  SkullMesh defective;  ///< the skull without the defect: closed, outward-oriented
  SkullMesh implant;    ///< the removed bone: closed, outward-oriented
  double removed_volume_mm3 = 0.0;
  double seconds = 0.0;
  bool usable() const { return status == Status::Injected; }
};

/// The point lies in the defect's shape (sphere, cube or flap).
bool in_defect(const InjectDefectParams& params, const Eigen::Vector3d& x);

/// Voxelises the (closed) skull, splits the voxels into those inside and outside the shape and
/// turns both back into surfaces; defective ∪ implant is the skull and they do not overlap (at
/// the voxel level).
InjectDefectResult inject_defect(const SkullMesh& skull, const InjectDefectParams& params);

}  // namespace cranioplan
