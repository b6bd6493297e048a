#pragma once
// Known answers for the commonest cranioplasty: where a decompressive craniectomy would have
// removed the bone flap of a healthy skull. One-sided (fronto-temporo-parietal, a strip kept over
// the sagittal sinus, down to the temporal floor) or bifrontal (across the forehead above the
// orbits, in one piece or with a bar of bone kept over the midline). The cut itself is
// inject_defect's (InjectDefectParams::Shape::Flap).
#include <optional>
#include <string>

#include "cranioplan/algorithms/quality/inject_defect.h"
#include "cranioplan/model/mesh.h"
#include "cranioplan/model/plane.h"

namespace cranioplan {

class SurfaceLocator;

struct FlapPlacementParams {
  enum class Kind { OneSided, Bifrontal };
  Kind kind = Kind::OneSided;
  /// One-sided: the patient's side, +1 left (+x in LPS), −1 right.
  int side = 1;
  /// Along the outer table: one-sided, front to back; bifrontal, side to side, mm (40..300).
  double length_mm = 140.0;
  /// Along the outer table across that: one-sided, top to bottom; bifrontal, front to back,
  /// mm (30..200).
  double width_mm = 110.0;
  /// Bone kept on each side of the midsagittal plane, mm (0..40): one-sided, the strip over
  /// the sagittal sinus (15–20 mm); bifrontal, 0 for one flap across the midline, else a bar
  /// between two flaps.
  double midline_margin_mm = 15.0;
  /// One-sided, the flap's centre lies this far in front of the vault's centre, degrees (−30..30).
  double forward_deg = 10.0;
  /// The flap's lower edge lies this far above the floor of the cranial fossae (FlapCut::floor:
  /// the plane through where rays from the vault's centre first meet the anterior fossa's floor
  /// in front and the middle fossa's at the side, sloping down towards the back), mm (0..40).
  double above_floor_mm = 5.0;
};

struct FlapPlacement {
  std::optional<FlapCut> cut;    ///< none when the skull's vault or floor was not found
  std::string message;           ///< what was placed, or why nothing was
  double outer_radius_mm = 0.0;  ///< the outer table's distance from the apex along the axis
};

/// Places a flap on a complete skull whose midsagittal plane is `plane`, in the patient's frame
/// (LPS: anterior −y, superior +z, projected onto the plane): the apex at the vault's centre
/// (vault_center), the lower edge `above_floor_mm` above the fossae's floor as rays from the
/// apex meet it.
FlapPlacement place_flap(const SkullMesh& skull, const SurfaceLocator& bone, const Plane& plane,
                         const FlapPlacementParams& params);

}  // namespace cranioplan
