#pragma once
// Where is the defect? Rays from inside the skull: the directions in which no bone is met form
// openings; the skull base (or the cut of a scan) is the one that points away from the vault, a
// defect the largest other one that is large enough. The vault's direction is read from the
// skull itself (the rays that cross a regular two-table shell or an opening), and the rays are
// laid out in the skull's own frame, so the skull may come in any pose. Works whether or not the
// defect crosses the midline.
#include <optional>
#include <string>
#include <vector>

#include "cranioplan/algorithms/io/mesh_report.h"
#include "cranioplan/model/mesh.h"
#include "cranioplan/model/plane.h"

namespace cranioplan {

class SurfaceLocator;

/// A side of the surface where the scan ended: the plane of a flat cut at the surface's border
/// (`normal` points out of the surface; the plane is normal·x = offset), the surface's bounding
/// box (a cap's own box, for a closed surface) and the cut's outline.
struct ScanBorder {
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();
  double offset = 0.0;
  Eigen::Vector3d box_min = Eigen::Vector3d::Zero(), box_max = Eigen::Vector3d::Zero();
  /// The cut's outline, convex and counter-clockwise about `normal`: the hull of an open cut's
  /// loops on this side (BoundaryLoop::outline), or a cap's (BorderCap::outline).
  std::vector<Eigen::Vector3d> outline;
  std::string side;  ///< which border (BoundaryLoop::border)
  /// The ray from `from` along `dir` reaches the plane within the box's extent and within the
  /// outline (when it has three corners or more).
  bool reached_by(const Eigen::Vector3d& from, const Eigen::Vector3d& dir) const;
};

/// The sides where a surface ends along a flat cut at its border, where a scan ended or an
/// exporter cropped: open there (MeshReport's loops `at_border`) or closed by a flat cap
/// (MeshReport's caps: a padded import), one per side; none for a closed surface without caps.
std::vector<ScanBorder> scan_borders(const MeshReport& report);

struct DetectDefectParams {
  int directions = 20000;       ///< rays cast (Fibonacci sphere), 2,000..200,000
  double min_area_mm2 = 300.0;  ///< smaller openings are not defects (at the rim's radius)
  /// Width of the ring of intact bone around the rim on which support markers are proposed.
  double support_width_mm = 12.0;
  /// Rays whose inner and outer bone are farther apart than this met other bone on the way
  /// (e.g. the orbital roof): not used for the rim or the support ring, mm. 20 mm: a ray
  /// through both walls of the frontal sinus crosses 15–20 mm of the brow, and is the rim.
  double max_thickness_mm = 20.0;
  /// Rays that only graze bone (at the cut face of a defect) pass through less than this; the
  /// rim is placed where rays still cross this much bone, mm.
  double min_thickness_mm = 1.5;
  /// With several openings large enough, the one seen in the direction of this point (e.g. a
  /// click near the defect, mm) rather than the largest.
  std::optional<Eigen::Vector3d> near;
  /// Where the rays start, a point inside the cranial cavity (detect_defect_near_plane; mm).
  /// Unset: from the vault's centre (vault_center) towards a small opening, or the skull's
  /// surface centroid on the midsagittal plane for a large one (detect_defect_near_plane). Set,
  /// the plan's dependence on its own rays can be measured (docs/AUTOPLAN.md).
  std::optional<Eigen::Vector3d> center;
  /// The rays' lattice is turned by this rotation (columns: its axes in the skull's
  /// coordinates). With the skull's own frame (skull_frame) the rays meet the same anatomy
  /// whatever pose the file came in, and so the plan is the same.
  std::optional<Eigen::Matrix3d> frame;
  /// Where the scan ended (scan_borders). A ray that meets no bone and reaches such a border
  /// is closed there by the scan's end, not open in the bone: the cut is never planned as a
  /// defect, and a defect that reaches the cut keeps its own rays. Not a user's parameter:
  /// unset, detect_defect_near_plane finds them from the mesh; a caller that has the mesh's
  /// report already (a skull mesh read by load_skull) gives them from it, and an empty list
  /// says the scan ended nowhere. detect_defect takes unset as none.
  std::optional<std::vector<ScanBorder>> scan_borders;
  /// The rim traced on the bone itself (trace_rim.h) from where the rays saw it, so that the
  /// stretches of the edge the rays graze or cannot reach are found too; the opening is then
  /// every ray inside the traced rim. false: the rim the rays saw (the quick look a ray start
  /// is chosen from, detect_defect_near_plane).
  bool trace_rim_on_bone = true;
  /// The rim is traced on the bone for an opening at least this large (mm², at the rays' rim
  /// radius), for one whose rays' rim leaves a stretch of `trace_from_unseen_mm` or more
  /// unseen, and for one that runs into the scan's end (there no ray sees a rim; the traced one
  /// follows the border's plane). A smaller opening the rays saw all round keeps
  /// their rim: there the rays see the edge nearly square, and their rim moves less with the
  /// rays' start than the traced one (docs/AUTOPLAN.md, "The rim traced on the bone").
  double trace_from_area_mm2 = 3000.0;
  double trace_from_unseen_mm = 25.0;
};

/// Gives `params` the scan's borders from the report a skull mesh was read with
/// (LoadedSkull::report), unless they are set already; without a report (a skull from a volume)
/// they stay unset, to be found from the mesh. The same borders either way: this saves finding
/// them again.
void take_scan_borders(DetectDefectParams& params, const std::optional<MeshReport>& report);

/// The planes of `borders` (where the skull's scan ended) that `implant` was cut at: an implant
/// planned up to the scan's end is cut flat there (ImplantParams::scan_ends), so at least
/// kScanEndVertices of its vertices lie within kOnScanEndMm of the plane and none further than
/// kOnScanEndMm + 0.5 mm beyond it. For checking such an implant on its own (`qa`): its flat side
/// meets no bone, and no gap to bone is counted along it (QualityParams::scan_ends).
std::vector<Plane> scan_ends_met(const SkullMesh& implant, const std::vector<ScanBorder>& borders);
inline constexpr int kScanEndVertices = 30;
inline constexpr double kOnScanEndMm = 1.0;

/// A stretch of the rim that no ray saw: between two consecutive rim points far apart, where
/// the outline is interpolated (straight from one to the other).
struct RimStretch {
  Eigen::Vector3d from = Eigen::Vector3d::Zero(), to = Eigen::Vector3d::Zero();
  double length_mm() const { return (to - from).norm(); }
};

struct DefectRegion {
  enum class Status { Found, NoDefect };
  Status status = Status::NoDefect;
  std::string message;
  Eigen::Vector3d center = Eigen::Vector3d::Zero();  ///< where the rays start (inside the skull)
  Eigen::Vector3d axis = Eigen::Vector3d::Zero();    ///< mean direction of the opening (unit)
  double area_mm2 = 0.0;                             ///< opening area at the rim's radius
  /// The skull's superior direction as the rays saw it: the mean direction of the rays that
  /// cross a regular shell (both tables, facing the ray) or an opening — the vault. Unit; zero
  /// on a shell closed all round (no direction, and no base).
  Eigen::Vector3d up = Eigen::Vector3d::Zero();
  /// The axes the rays were laid out in (DetectDefectParams::frame; identity without one).
  Eigen::Matrix3d frame = Eigen::Matrix3d::Identity();
  int other_openings = 0;  ///< further openings large enough to be defects (not planned)
  /// A ray from `center` through each of them (unit; the opening's ray nearest its mean
  /// direction; largest first, or after the one `near` chose): a point `center + r·axis` on
  /// one, as `DetectDefectParams::near`, plans that opening.
  std::vector<Eigen::Vector3d> other_axes;
  std::vector<Eigen::Vector3d> hole_directions;  ///< unit rays through the opening
  /// The rim: the last bone met along rays next to the opening, outer and inner table, in
  /// order around the axis (same count, paired).
  std::vector<Eigen::Vector3d> outer_rim, inner_rim;
  /// Stretches of the rim no ray saw (unseen_rim_stretches, longest first): its rays there
  /// graze the bone or meet other bone first (along an orbit), so the outline there is
  /// interpolated between rim points far apart. The message names them; the wizard draws them.
  std::vector<RimStretch> unseen_rim;
  /// The rim was traced on the bone (DetectDefectParams::trace_rim_on_bone): `outer_rim` is the
  /// outer table's edge about 1 mm apart all round, and `unseen_rim` is empty.
  bool rim_traced = false;
  /// Stretches where the traced rim runs along the scan's end (the mesh's open border or a flat
  /// cap) rather than a cut face: the opening reaches the scan's border there, and the bone
  /// beyond it is unknown.
  std::vector<RimStretch> at_scan_border;
  /// The planes of the borders the traced rim runs along (ScanBorder's normal and offset: the
  /// normal points out of the scanned volume): the implant ends there (ImplantParams::scan_ends).
  std::vector<Plane> scan_ends;
  /// With DetectDefectParams::near: the angle, seen from `center`, between the point and the
  /// opening's nearest ray, degrees (0 when the point lies in the opening's direction). Over
  /// kNearMissDeg the message says that no opening lies towards the point.
  double near_miss_deg = 0.0;
  double seconds = 0.0;
  bool found() const { return status == Status::Found; }
  /// What was found, said from the fields above: the opening's area, the further openings
  /// (left unplanned, or `others_planned` as well, as `autoplan --all-openings` does), a point
  /// that missed every opening, the rim's unseen stretches. `message` is this with
  /// `others_planned` false.
  std::string describe(bool others_planned = false) const;
};

/// A point given to choose the opening (DetectDefectParams::near) that lies further than this
/// from every ray through the opening planned, degrees, is said to miss it (a point on the rim
/// lies within a ray spacing or two, about 3°).
inline constexpr double kNearMissDeg = 10.0;

/// A rim stretch without a rim point is reported when it is longer than this (mm) and than
/// kUnseenRimTimesMedian times the rim's median spacing (large openings have sparser rims).
constexpr double kUnseenRimMm = 10.0;
constexpr double kUnseenRimTimesMedian = 4.0;

/// The gaps between consecutive points of a closed rim (in order around the opening, the last
/// followed by the first) longer than `min_gap_mm` and than `times_median` times the median
/// gap, longest first.
std::vector<RimStretch> unseen_rim_stretches(const std::vector<Eigen::Vector3d>& rim,
                                             double min_gap_mm = kUnseenRimMm,
                                             double times_median = kUnseenRimTimesMedian);

/// The skull's own axes, the same on the skull in any pose: the principal axis of the vertices
/// within the midsagittal plane, the other axis within it, and the plane's normal (columns,
/// right-handed). Each in-plane axis points where the vertices are skewed (a skull is lopsided
/// both ways: the face in front, the base below). `center` lies on the plane.
Eigen::Matrix3d skull_frame(const SkullMesh& skull, const Eigen::Vector3d& center,
                            const Eigen::Vector3d& plane_normal);

/// A unit vector across `axis`, taken from `frame`'s axes (the last one not nearly along it),
/// so that angles around the axis start from the same anatomy in any pose.
Eigen::Vector3d across_axis(const Eigen::Vector3d& axis, const Eigen::Matrix3d& frame);

/// What a ray from `center` (inside the skull) in direction `dir` meets: the first bone from
/// the centre (inner table) and, coming back from `reach` mm out, the first bone from outside
/// (outer table). `paired` when both are met between `min_thickness_mm` and `max_thickness_mm`
/// apart (the ray crosses one plausible layer of bone).
struct RayThroughBone {
  std::optional<Eigen::Vector3d> inner, outer;
  /// The surface's outward normals where the ray meets it (zero when not met): parallel tables
  /// give opposite normals; a cut face met instead of a table does not.
  Eigen::Vector3d inner_normal = Eigen::Vector3d::Zero(), outer_normal = Eigen::Vector3d::Zero();
  bool paired = false;
};
RayThroughBone cast_through_bone(const SurfaceLocator& locator, const Eigen::Vector3d& center,
                                 const Eigen::Vector3d& dir, double reach, double min_thickness_mm,
                                 double max_thickness_mm);

/// The centre of the vault as the rays see it: from `start` (inside the cranial cavity, on
/// `plane`), rays in 4,000 directions; the inner-table hits of those that cross a regular
/// two-table shell (both tables facing the ray within 45°) are fitted with a sphere (least
/// squares, then again without the hits more than 2.5 median deviations + 0.5 mm off it); its
/// centre moved onto the plane is the next start, until it moves less than 0.05 mm (at most 10
/// times). `radius_mm` gets the sphere's radius. Nothing when fewer than 100 rays cross the
/// vault or the hits lie in a plane.
std::optional<Eigen::Vector3d> vault_center(const SurfaceLocator& locator, const Plane& plane,
                                            const Eigen::Vector3d& start,
                                            double* radius_mm = nullptr);

/// `center`: a point inside the cranial cavity (e.g. the skull's centroid moved onto the
/// midsagittal plane).
DefectRegion detect_defect(const SkullMesh& skull, const SurfaceLocator& locator,
                           const Eigen::Vector3d& center, const DetectDefectParams& params = {});

}  // namespace cranioplan
