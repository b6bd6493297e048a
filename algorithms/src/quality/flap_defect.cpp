#include "cranioplan/algorithms/quality/flap_defect.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include "cranioplan/algorithms/geometry/surface_locator.h"
#include "cranioplan/algorithms/planning/detect_defect.h"

namespace cranioplan {
namespace {

constexpr double kDeg = M_PI / 180.0;
constexpr double kReach = 400.0;

// The direction at `elevation` (radians) above the horizontal `out`, towards `up`.
Eigen::Vector3d at_elevation(const Eigen::Vector3d& out, const Eigen::Vector3d& up,
                             double elevation) {
  return (std::cos(elevation) * out + std::sin(elevation) * up).normalized();
}

// Where the floor of a cranial fossa begins below the wall in direction `out`: going down from
// 40° above it in 1° steps, the first ray from `apex` whose first bone lies much nearer than
// the wall above (the floor, met obliquely) or that meets no bone; its first bone. Nothing when
// no wall is seen above or no floor below.
std::optional<Eigen::Vector3d> floor_point(const SurfaceLocator& bone, const Eigen::Vector3d& apex,
                                           const Eigen::Vector3d& out, const Eigen::Vector3d& up) {
  std::vector<double> wall;
  for (int deg = 40; deg >= 0; deg -= 2) {
    const RayThroughBone h =
        cast_through_bone(bone, apex, at_elevation(out, up, deg * kDeg), kReach, 1.0, 20.0);
    if (h.paired) wall.push_back((*h.inner - apex).norm());
  }
  if (wall.size() < 5) return std::nullopt;
  std::nth_element(wall.begin(), wall.begin() + wall.size() / 2, wall.end());
  const double typical = wall[wall.size() / 2];
  std::optional<Eigen::Vector3d> last_wall;
  for (int deg = 40; deg >= -70; --deg) {
    const RayThroughBone h =
        cast_through_bone(bone, apex, at_elevation(out, up, deg * kDeg), kReach, 1.0, 20.0);
    if (!h.inner) return last_wall;
    if ((*h.inner - apex).norm() < 0.85 * typical) return *h.inner;
    last_wall = *h.inner;
  }
  return std::nullopt;
}

double outer_radius(const SurfaceLocator& bone, const Eigen::Vector3d& apex,
                    const Eigen::Vector3d& dir) {
  const auto out = bone.first_hit(apex + kReach * dir, apex);
  return out ? (out->point - apex).norm() : 0.0;
}

// The angle above the horizontal `out` at which `p` is seen from `apex`, towards `up`.
double elevation_of(const Eigen::Vector3d& p, const Eigen::Vector3d& apex,
                    const Eigen::Vector3d& up) {
  const Eigen::Vector3d d = (p - apex).normalized();
  return std::asin(std::clamp(d.dot(up), -1.0, 1.0));
}

}  // namespace

FlapPlacement place_flap(const SkullMesh& skull, const SurfaceLocator& bone, const Plane& plane,
                         const FlapPlacementParams& params) {
  FlapPlacement r;
  const std::optional<Eigen::Vector3d> apex =
      vault_center(bone, plane, plane.project(vertex_centroid(skull)));
  if (!apex) {
    r.message = "no vault found to place a flap on";
    return r;
  }
  // The patient's directions (LPS) on the plane, and the plane's normal towards the side.
  const Eigen::Vector3d n = plane.normal.normalized();
  const Eigen::Vector3d up = unit_across(Eigen::Vector3d::UnitZ(), n);
  Eigen::Vector3d front = up.cross(n);
  if (front.dot(-Eigen::Vector3d::UnitY()) < 0.0) front = -front;
  const bool bifrontal = params.kind == FlapPlacementParams::Kind::Bifrontal;
  const double side = params.side >= 0 ? 1.0 : -1.0;
  const Eigen::Vector3d lateral = n.dot(Eigen::Vector3d::UnitX()) * side >= 0 ? n : -n;
  // The flap's outward direction in the horizontal: to the side (a little forward), or forward.
  const double fwd = std::clamp(params.forward_deg, -30.0, 30.0) * kDeg;
  const Eigen::Vector3d out =
      bifrontal ? front : (std::cos(fwd) * lateral + std::sin(fwd) * front).normalized();
  const double length = std::clamp(params.length_mm, 40.0, 300.0);
  const double width = std::clamp(params.width_mm, 30.0, 200.0);
  // The fossae's floor. One-sided: the middle fossa's at the side, and the anterior fossa's
  // (the orbital roof) below the flap's front end; a plane through both across the head, rising
  // from the temporal fossa to the orbital roof. Bifrontal: the anterior fossa's in front, the
  // plane sloping down towards the back.
  const double side_radius = outer_radius(bone, *apex, out);
  if (!(side_radius > 0.0)) {
    r.message = "no bone met where the flap would be";
    return r;
  }
  const double front_end = std::min(fwd + 0.5 * length / side_radius, 80.0 * kDeg);
  const Eigen::Vector3d front_out =
      bifrontal ? front
                : (std::cos(front_end) * lateral + std::sin(front_end) * front).normalized();
  const std::optional<Eigen::Vector3d> front_floor = floor_point(bone, *apex, front_out, up);
  const std::optional<Eigen::Vector3d> side_floor =
      bifrontal ? front_floor : floor_point(bone, *apex, out, up);
  if (!front_floor || !side_floor) {
    r.message = "the floor of the cranial fossae was not found below the flap";
    return r;
  }
  const double above = std::clamp(params.above_floor_mm, 0.0, 40.0);
  Eigen::Vector3d floor_normal;
  if (bifrontal) {
    constexpr double kSlope = 20.0 * kDeg;  // down towards the back
    floor_normal = (std::cos(kSlope) * up - std::sin(kSlope) * front).normalized();
  } else {
    const Eigen::Vector3d run = *front_floor - *side_floor;
    const Eigen::Vector3d level = unit_across(up.cross(run), up);  // horizontal, across `run`
    floor_normal = run.cross(level).normalized();
    if (floor_normal.dot(up) < 0.0) floor_normal = -floor_normal;
  }
  const Plane floor = Plane::through(*side_floor + above * up, floor_normal);
  // The ellipse's lower edge at the floor where it meets the side's wall; its half-angles follow
  // the outer table's radius at the flap's centre, found again as the centre moves up.
  const double lower_edge = elevation_of(*side_floor + above * up, *apex, up);
  double radius = side_radius;
  Eigen::Vector3d axis = out;
  for (int round = 0; round < 3 && radius > 0.0; ++round) {
    axis = at_elevation(out, up, lower_edge + 0.5 * width / radius);
    radius = outer_radius(bone, *apex, axis);
  }
  if (!(radius > 0.0)) {
    r.message = "no bone met where the flap would be";
    return r;
  }
  FlapCut cut;
  cut.apex = *apex;
  cut.axis = axis;
  cut.along = unit_across(bifrontal ? lateral : front, axis);
  cut.half_length_rad = 0.5 * length / radius;
  cut.half_width_rad = 0.5 * width / radius;
  cut.midline = plane;
  cut.midline_margin_mm = std::clamp(params.midline_margin_mm, 0.0, 40.0);
  cut.one_side = bifrontal ? 0 : (plane.normal.dot(lateral) > 0 ? 1 : -1);
  cut.floor = floor;
  r.cut = cut;
  r.outer_radius_mm = radius;
  char buf[200];
  std::snprintf(buf, sizeof(buf), "%s flap %.0f × %.0f mm, %.0f mm off the midline",
                bifrontal  ? "bifrontal"
                : side > 0 ? "left"
                           : "right",
                length, width, cut.midline_margin_mm);
  r.message = buf;
  return r;
}

}  // namespace cranioplan
