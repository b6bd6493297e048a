#pragma once
// The edge of an opening, found on the bone itself. The rays that detect an opening
// (detect_defect.h) say where it is, but where its edge runs at a grazing angle to them, or lies
// behind other bone as seen from their start (the floor of the middle fossa below a
// decompressive craniectomy), no ray meets the last bone. The rim is where the outer table ends
// at the opening's cut face: a closed curve on the skull's surface, found here without rays
// from the centre.
//
// A face of the skull belongs to the outer table when (1) it faces away from the centre and (2)
// the bone under it has two tables: a short probe from it inwards, along its own (smoothed)
// normal, leaves the bone through a surface facing back within `table_angle_deg`, within
// `max_thickness_mm`. A cut face fails (2) whatever its angle to the centre: probed along its
// own normal it runs along the bone plate and leaves through a table side-on. The outer table
// is grown over the mesh from faces next to the opening that the rays did see, and its boundary
// is a set of closed loops; the rim is the loop that winds once around the opening's axis
// nearest to it. The inner rim likewise on the inner table (facing the centre). Where the loop
// runs along the mesh's own open border or along a flat cap where the scan ended, the opening
// reaches the scan's border: the bone beyond it is unknown. Across the stretch where the
// opening itself runs into the scan's end no bone edges it: there the loop runs along the
// border's plane, where the table (at the distance of the bone on either side) would cross it.
#include <Eigen/Core>
#include <string>
#include <vector>

#include "cranioplan/model/mesh.h"

namespace cranioplan {

class SurfaceLocator;
struct ScanBorder;

struct TraceRimParams {
  /// The faces examined lie within this angle (seen from the centre) beyond the opening's
  /// widest ray, deg (5..90).
  double band_deg = 30.0;
  /// The bone's far side faces back within this angle of the face's normal, deg (10..80).
  double table_angle_deg = 40.0;
  /// A table's bone is at most this thick along the face's normal, mm (the detection's
  /// max_thickness_mm).
  double max_thickness_mm = 20.0;
  /// A table faces away from (outer) or towards (inner) the centre by at least this cosine
  /// (0..1).
  double min_facing = 0.05;
  /// Spacing of the rim's points, mm (0.25..5).
  double spacing_mm = 1.0;
  /// The opening runs into the scan's end (rays next to it leave through a border): the rim may
  /// also run along the borders' planes, where the table would cross them. Otherwise only the
  /// table's own edge is followed.
  bool along_scan_end = false;
};

struct TracedRim {
  enum class Status { Traced, NotTraced };
  Status status = Status::NotTraced;
  std::string message;  ///< why it was not traced
  /// The rim on the outer table, a closed loop in order of increasing angle around the axis
  /// (seen from the centre), about `spacing_mm` apart.
  std::vector<Eigen::Vector3d> outer;
  /// The inner table's rim nearest each outer point (the same count); where the inner table
  /// was not traced, empty.
  std::vector<Eigen::Vector3d> inner;
  /// For each outer point: the loop runs there along the scan's end (the mesh's open border or
  /// a flat cap), not along a cut face of the bone.
  std::vector<char> at_scan_border;
  size_t faces_examined = 0;  ///< faces whose tables were probed
  double seconds = 0.0;
  bool traced() const { return status == Status::Traced; }
};

/// Traces the rim of the opening whose rays from `center` are `hole_directions` (unit) around
/// `axis` (unit), `e1` (unit, across the axis) fixing where angles around it start.
/// `seen_rim`, `seen_inner_rim`: the rim the rays saw (outer and inner table), which the traced
/// edge passes through where it can. `outer_seeds` and `inner_seeds`: points on the outer and
/// inner table next to the opening (bone the rays met), from which the tables are grown.
/// `borders`: where the scan ended (scan_borders), whose flat caps are the scan's end, not the
/// bone's.
TracedRim trace_rim_on_bone(const SkullMesh& skull, const SurfaceLocator& bone,
                            const Eigen::Vector3d& center, const Eigen::Vector3d& axis,
                            const Eigen::Vector3d& e1,
                            const std::vector<Eigen::Vector3d>& hole_directions,
                            const std::vector<Eigen::Vector3d>& seen_rim,
                            const std::vector<Eigen::Vector3d>& seen_inner_rim,
                            const std::vector<Eigen::Vector3d>& outer_seeds,
                            const std::vector<Eigen::Vector3d>& inner_seeds,
                            const std::vector<ScanBorder>& borders,
                            const TraceRimParams& params = {});

/// The directions among `dirs` (unit, from `center`) that lie inside the closed `loop` as seen
/// from `center` (its azimuthal equidistant projection around `axis`, `e1` across it).
std::vector<char> inside_loop(const std::vector<Eigen::Vector3d>& dirs,
                              const std::vector<Eigen::Vector3d>& loop,
                              const Eigen::Vector3d& center, const Eigen::Vector3d& axis,
                              const Eigen::Vector3d& e1);

}  // namespace cranioplan
