#include "cranioplan/algorithms/implant/perforate.h"

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <algorithm>
#include <cassert>
#include <chrono>
#include <cmath>
#include <cstdio>

#include "cranioplan/algorithms/geometry/distance_transform.h"
#include "cranioplan/algorithms/geometry/mesh_distance_field.h"
#include "cranioplan/algorithms/geometry/point_index.h"
#include "cranioplan/algorithms/geometry/surface_locator.h"
#include "cranioplan/algorithms/geometry/voxelize_mesh.h"
#include "cranioplan/algorithms/io/extract_bone_surface.h"

namespace cranioplan {

namespace {

// Holes added or taken away one by one: far more than a plate can hold.
constexpr size_t kMaxHoles = 1000;

// The holes' rims are rounded over this radius, mm: a sharp rim is a thin edge, and
// deburring one is the first thing a workshop does.
constexpr double kRimRoundMm = 1.0;
// A pattern hole is left out when its rim leaves material thinner than the minimum reaching
// more than this out of the thick material (the quality report's default limit for a corner,
// QualityParams::max_corner_mm), mm, within this much of the rim's rounding, mm; the rest are
// drilled again, at most this many times.
constexpr double kCornerMm = 0.8, kCornerNearMm = 2.0;
constexpr int kDrillRounds = 3;

// The implant's faces by the side they face: away from the inside point (outer), towards it
// (inner), or across (the side wall).
struct Faces {
  std::vector<Eigen::Vector3d> outer_centres, outer_normals;
  std::vector<double> outer_areas;
  std::vector<Eigen::Vector3d> wall_points;  // the side wall's face centres: the edge
};

Faces classify(const SkullMesh& implant, const Eigen::Vector3d& inside) {
  Faces f;
  for (auto fh : implant.faces()) {
    const FaceCorners corners = face_corners(implant, fh);
    const auto& p = corners.p;
    const Eigen::Vector3d cross = corners.cross();
    if (cross.norm() == 0) continue;
    const Eigen::Vector3d c = (p[0] + p[1] + p[2]) / 3.0, n = cross.normalized();
    const double facing = n.dot((c - inside).normalized());
    if (facing > 0.7) {
      f.outer_centres.push_back(c);
      f.outer_normals.push_back(n);
      f.outer_areas.push_back(0.5 * cross.norm());
    } else if (facing > -0.7) {
      f.wall_points.push_back(c);
    }
  }
  return f;
}

// The outer surface's normal around `at`: the mean of its faces' within 1.5 mm.
Eigen::Vector3d normal_near(const Faces& f, const PointIndex& outer, const Eigen::Vector3d& at,
                            const Eigen::Vector3d& inside) {
  Eigen::Vector3d n = Eigen::Vector3d::Zero();
  for (int i : outer.within_radius(at, 1.5)) n += f.outer_areas[i] * f.outer_normals[i];
  if (n.norm() == 0) n = at - inside;
  return n.normalized();
}

// The pattern: a hexagonal lattice over the plane across the outer surface's mean normal,
// centred at its area-weighted centroid, each point carried along that normal onto the outer
// surface; kept where it lies far enough from the edge and the implant is thick enough there.
std::vector<Eigen::Vector3d> pattern_centres(const Faces& f, const SurfaceLocator& self,
                                             const PointIndex& wall, const PerforationParams& p) {
  Eigen::Vector3d axis = Eigen::Vector3d::Zero(), centroid = Eigen::Vector3d::Zero();
  double area = 0.0;
  for (size_t i = 0; i < f.outer_centres.size(); ++i) {
    axis += f.outer_areas[i] * f.outer_normals[i];
    centroid += f.outer_areas[i] * f.outer_centres[i];
    area += f.outer_areas[i];
  }
  if (area == 0 || axis.norm() == 0) return {};
  axis.normalize();
  centroid /= area;
  const Eigen::Vector3d e1 = axis.unitOrthogonal(), e2 = axis.cross(e1);
  double reach = 0.0;
  for (const auto& c : f.outer_centres) reach = std::max(reach, (c - centroid).norm());
  const double s = p.spacing_mm, row = s * std::sqrt(3.0) / 2.0;
  const int rows = static_cast<int>(reach / row) + 1, cols = static_cast<int>(reach / s) + 1;
  std::vector<Eigen::Vector3d> out;
  for (int j = -rows; j <= rows; ++j)
    for (int i = -cols; i <= cols; ++i) {
      const double u = (i + ((j & 1) ? 0.5 : 0.0)) * s, v = j * row;
      const Eigen::Vector3d q = centroid + u * e1 + v * e2;
      const auto hit = self.first_hit(q + (reach + 50.0) * axis, q - (reach + 50.0) * axis);
      if (!hit || self.face_normal(hit->face).dot(axis) <= 0.0) continue;
      double d2 = 0.0;
      if (!f.wall_points.empty()) wall.nearest(hit->point, &d2);
      if (!f.wall_points.empty() && std::sqrt(d2) < p.edge_distance_mm) continue;
      const auto back = self.first_hit(hit->point - 1e-3 * axis, hit->point - 50.0 * axis);
      if (back && back->distance >= p.min_thickness_mm + 2.0) out.push_back(hit->point);
    }
  return out;
}

}  // namespace

std::string perforation_problem(const PerforationParams& p) {
  if (std::string problem = range_problems("the holes'", p); !problem.empty()) return problem;
  const ParamSpec spacing = spec_of<PerforationParams>("spacing_mm");
  if (p.spacing_mm < p.diameter_mm + 2.0)
    return spacing.problem("the holes'", p.spacing_mm, p.diameter_mm + 2.0, spacing.max);
  if (p.added.size() > kMaxHoles || p.removed.size() > kMaxHoles)
    return "at most " + std::to_string(kMaxHoles) + " holes may be added or taken away";
  for (const auto& v : p.added)
    if (!v.allFinite()) return "a hole's position is not a point";
  for (const auto& v : p.removed)
    if (!v.allFinite()) return "a hole's position is not a point";
  return {};
}

bool hole_goes_through(const SurfaceLocator& locator, const Hole& hole) {
  return !locator.first_hit(hole.center + 15.0 * hole.axis, hole.center - 15.0 * hole.axis);
}

namespace {

// The plate under a hole, along lines parallel to `axis` through its centre and on two rings
// (half `reach` and `reach` off the axis, 8 directions each), each followed from above the
// outer surface to its first and second crossing (the plate's two surfaces), at most 16 mm
// down: not on into another part of a curved implant. Lines that miss the plate (past its
// edge) are left out. `above` and `depth`: how far the outer surface rises above the centre
// and the inner one lies below it along the axis, the most of any line; `inner`: where the
// lines leave the plate.
struct PlateUnder {
  double above = 0.0, depth = 0.0;
  bool under_centre = false;  // the centre's line leaves the plate within 16 mm
  std::vector<Eigen::Vector3d> inner;
};
PlateUnder plate_under(const SurfaceLocator& self, const Eigen::Vector3d& center,
                       const Eigen::Vector3d& axis, double reach) {
  constexpr double kFrom = 3.0, kDown = 16.0;
  const Eigen::Vector3d u = axis.unitOrthogonal(), v = axis.cross(u);
  PlateUnder plate;
  for (int ring = 0; ring < 3; ++ring)
    for (int k = 0; k < (ring == 0 ? 1 : 8); ++k) {
      const double phi = 2.0 * M_PI * k / 8.0, rho = 0.5 * ring * reach;
      const Eigen::Vector3d o = center + rho * (std::cos(phi) * u + std::sin(phi) * v);
      const auto top = self.first_hit(o + kFrom * axis, o - kDown * axis);
      if (!top) continue;
      const double t_top = kFrom - top->distance;
      plate.above = std::max(plate.above, t_top);
      const auto under = self.first_hit(top->point - 1e-3 * axis, o - kDown * axis);
      if (!under) {
        plate.depth = std::max(plate.depth, kDown);
        continue;
      }
      plate.depth = std::max(plate.depth, under->distance + 1e-3 - t_top);
      plate.inner.push_back(under->point);
      plate.under_centre = plate.under_centre || ring == 0;
    }
  if (!plate.under_centre) plate.depth = std::max(plate.depth, 15.0);
  return plate;
}

// The plate's mid-normal at a hole: halfway between the outer normal `axis` and the inner
// surface's normal under the hole (the plane fitted to where the plate_under lines leave it,
// turned outward; a marching-cubes facet's own normal is a staircase's). `axis` when fewer
// than five lines leave the plate.
Eigen::Vector3d mid_normal(const SurfaceLocator& self, const Hole& hole, double reach) {
  const PlateUnder plate = plate_under(self, hole.center, hole.axis, reach);
  if (plate.inner.size() < 5) return hole.axis;
  Eigen::Vector3d c = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& q : plate.inner) c += q;
  c /= static_cast<double>(plate.inner.size());
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  for (const Eigen::Vector3d& q : plate.inner) cov += (q - c) * (q - c).transpose();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(cov);
  Eigen::Vector3d n = eig.eigenvectors().col(0);
  if (n.dot(hole.axis) < 0.0) n = -n;
  const Eigen::Vector3d mid = hole.axis + n;
  return mid.norm() > 1e-6 ? mid.normalized() : hole.axis;
}

// Material of a field (positive inside) thinner than `min_thickness_mm` that reaches more than
// kCornerMm out of the material a ball of that diameter fits in: a corner the quality report
// refuses away from the bone (check_implant's measure of thin material, on this grid).
std::vector<uint8_t> thin_corners(const std::vector<float>& field, const VoxelGrid& g,
                                  double min_thickness_mm) {
  std::vector<uint8_t> solid(field.size());
  for (size_t c = 0; c < field.size(); ++c) solid[c] = field[c] > 0.0f;
  const double r = 0.5 * min_thickness_mm;
  const std::vector<uint8_t> centres = ball_centres(depth_in_mask(solid, g), g, r);
  const std::vector<float> to_core = distance_to_mask(centres, g, r + g.spacing + kCornerMm + 1.0);
  std::vector<uint8_t> thin(field.size(), 0);
  for (size_t c = 0; c < field.size(); ++c) thin[c] = solid[c] && to_core[c] - r > kCornerMm;
  return thin;
}

// Whether a voxel of `mask` lies within `reach` of the hole's axis, from 3 mm above its centre
// to 16 mm below (as deep as plate_under looks).
bool near_hole(const std::vector<uint8_t>& mask, const VoxelGrid& g, const Hole& hole,
               double reach) {
  bool near = false;
  for_voxels_near(g, hole.center, 16.0 + reach, [&](int i, int j, int k) {
    if (near || !mask[g.index(i, j, k)]) return;
    const Eigen::Vector3d q = g.center(i, j, k) - hole.center;
    const double t = q.dot(hole.axis);
    near = t <= 3.0 && t >= -16.0 && (q - t * hole.axis).norm() <= reach;
  });
  return near;
}

// The holes: the user's (on the implant's surface), then the pattern's that keep clear of them
// and of the removed, into `holes`; a problem to say when two of the user's lie too close.
std::string place_holes(const Faces& faces, const SurfaceLocator& self, const PointIndex& outer,
                        const PointIndex& wall, const Eigen::Vector3d& inside,
                        const PerforationParams& p, std::vector<Hole>& holes) {
  for (const Eigen::Vector3d& a : p.added) {
    const Eigen::Vector3d at = self.closest(a).point;
    holes.push_back({at, normal_near(faces, outer, at, inside), true});
  }
  for (size_t i = 0; i < holes.size(); ++i)
    for (size_t j = i + 1; j < holes.size(); ++j)
      if ((holes[i].center - holes[j].center).norm() < p.diameter_mm + 1.0)
        return "holes " + std::to_string(i + 1) + " and " + std::to_string(j + 1) +
               " are less than 1 mm apart: move or remove one";
  if (p.pattern)
    for (const Eigen::Vector3d& c : pattern_centres(faces, self, wall, p)) {
      bool keep = true;
      for (const Eigen::Vector3d& x : p.removed) keep = keep && (x - c).norm() > 0.5 * p.spacing_mm;
      for (const Eigen::Vector3d& x : p.added) keep = keep && (x - c).norm() > 0.5 * p.spacing_mm;
      if (keep) holes.push_back({c, normal_near(faces, outer, c, inside), false});
    }
  return {};
}

// One hole's cylinder taken from the implant's field (their smooth minimum, so that the rim
// comes out rounded). The drill goes from above the outer surface to below the inner one under
// all of it (plate_under; as plans saved before mid_normal: at the centre), not on into another
// part of a curved implant.
void carve(std::vector<float>& field, const VoxelGrid& g, const SurfaceLocator& self,
           const Hole& hole, const PerforationParams& p) {
  const double radius = 0.5 * p.diameter_mm, h = g.spacing;
  PlateUnder span;
  if (p.mid_normal) {
    span = plate_under(self, hole.center, hole.axis, radius + kRimRoundMm);
  } else {
    const auto under =
        self.first_hit(hole.center - 1e-3 * hole.axis, hole.center - 16.0 * hole.axis);
    span.depth = under ? under->distance : 15.0;
  }
  const double depth = span.depth + 1.0 + 2.0 * h, above = span.above + 1.0 + 2.0 * h;
  const double reach = p.mid_normal ? radius + kRimRoundMm + 2.0 * h + std::max(depth, above)
                                    : radius + 2.0 * h + 16.0;
  for_voxels_near(g, hole.center, reach, [&](int i, int j, int k) {
    const Eigen::Vector3d q = g.center(i, j, k) - hole.center;
    const double t = q.dot(hole.axis);
    if (t > above || t < -depth) return;
    const double off_axis = (q - t * hole.axis).norm();
    float& v = field[g.index(i, j, k)];
    v = static_cast<float>(smooth_min(v, off_axis - radius, kRimRoundMm));
  });
}

std::string drilled_message(size_t holes, double diameter_mm, int blocked, int left_out) {
  char buf[160];
  std::snprintf(buf, sizeof(buf), "%zu %s of %.1f mm drilled", holes, holes == 1 ? "hole" : "holes",
                diameter_mm);
  std::string message = buf;
  if (blocked > 0)
    message +=
        " (" + std::to_string(blocked) + (blocked == 1 ? " does" : " do") + " not go through)";
  if (left_out > 0)
    message += "; " + std::to_string(left_out) + " of the pattern's left out (" +
               (left_out == 1 ? "its rim" : "their rims") +
               " would leave a corner thinner than the material allows)";
  return message;
}

// perforate, the drilled implant meshed in `into` (the result's own mesh, or the caller's).
void perforate_into(const SkullMesh& implant, const Eigen::Vector3d& inside,
                    const PerforationParams& p, PerforateResult& r, SkullMesh& into) {
  assert(&into != &implant && "the holes are meshed into another mesh than the implant");
  const auto t0 = std::chrono::steady_clock::now();
  auto done = [&](PerforateResult& out) {
    out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  };
  if (const std::string problem = perforation_problem(p); !problem.empty()) {
    r.message = problem;
    into = implant;
    return done(r);
  }
  const Faces faces = classify(implant, inside);
  if (faces.outer_centres.empty()) {
    r.message = "the implant has no outer surface facing away from the skull's inside";
    into = implant;
    return done(r);
  }
  const SurfaceLocator self(implant);
  const PointIndex outer(faces.outer_centres);
  const PointIndex wall(faces.wall_points.empty() ? std::vector<Eigen::Vector3d>{inside}
                                                  : faces.wall_points);
  const double radius = 0.5 * p.diameter_mm;
  if (std::string problem = place_holes(faces, self, outer, wall, inside, p, r.holes);
      !problem.empty()) {
    r.message = std::move(problem);
    into = implant;
    r.holes.clear();
    return done(r);
  }
  if (r.holes.empty()) {  // nothing to drill: the implant as it is
    into = implant;
    r.status = PerforateResult::Status::Drilled;
    r.message = "no hole fits: the implant is smaller than the pattern's distance from its edge";
    return done(r);
  }

  // Along the plate's mid-normal, so that the hole leaves both surfaces alike.
  if (p.mid_normal)
    for (Hole& hole : r.holes) hole.axis = mid_normal(self, hole, radius + kRimRoundMm);
  // The implant as a field on a fine grid: its signed distance near its surface, less each
  // hole's cylinder (their smooth minimum, so the rims come out rounded).
  const auto [lo, hi] = mesh_bounds(implant);
  const double h0 = std::clamp(std::min(p.voxel_mm, p.diameter_mm / 4.0), 0.05, 1.0);
  const VoxelGrid g = VoxelGrid::covering_at_most(lo, hi, h0, std::max(1e5, p.max_voxels), 3);
  const std::vector<uint8_t> solid = voxelize_mesh(implant, g);
  // The implant's signed distance (mm, positive inside): exact near its surface, ±10 mm (no
  // more than needed) elsewhere.
  const std::vector<float> whole = signed_distance_near_surface(self, solid, g);
  // Drilled; then, with `sound_rims`, the pattern's holes whose rim leaves a corner thinner
  // than the material allows, reaching further out of the material that is thick enough than
  // the quality report allows (as it measures thin material), are left out and the rest
  // drilled again, up to three times.
  std::vector<float> field;
  std::vector<uint8_t> before;
  int left_out = 0;
  for (int round = 0;; ++round) {
    field = whole;
    for (const Hole& hole : r.holes) carve(field, g, self, hole, p);
    if (!p.sound_rims || !p.pattern || round == kDrillRounds) break;
    // Only the corners the holes made: the implant's own thin edge may lie within reach.
    if (before.empty()) before = thin_corners(whole, g, p.min_thickness_mm);
    std::vector<uint8_t> made = thin_corners(field, g, p.min_thickness_mm);
    for (size_t c = 0; c < made.size(); ++c) made[c] = made[c] && !before[c];
    std::vector<Hole> kept;
    for (const Hole& hole : r.holes)
      if (hole.added || !near_hole(made, g, hole, radius + kRimRoundMm + kCornerNearMm))
        kept.push_back(hole);
    if (kept.size() == r.holes.size()) break;
    left_out += static_cast<int>(r.holes.size() - kept.size());
    r.holes = std::move(kept);
  }
  ExtractBoneSurfaceResult s = surface_of_signed_distance(std::move(field), g, into, p.iso_gap);
  if (!s.usable()) {
    r.message = "drilling the holes: " + s.message;
    into = implant;
    r.holes.clear();
    return done(r);
  }
  const SurfaceLocator drilled(into);
  int blocked = 0;
  for (const Hole& hole : r.holes) blocked += !hole_goes_through(drilled, hole);
  r.status = PerforateResult::Status::Drilled;
  r.message = drilled_message(r.holes.size(), p.diameter_mm, blocked, left_out);
  return done(r);
}

}  // namespace

PerforateResult perforate(const SkullMesh& implant, const Eigen::Vector3d& inside,
                          const PerforationParams& params) {
  PerforateResult r;
  perforate_into(implant, inside, params, r, r.mesh);
  return r;
}

PerforateResult perforate(const SkullMesh& implant, const Eigen::Vector3d& inside,
                          const PerforationParams& params, SkullMesh& into) {
  PerforateResult r;
  perforate_into(implant, inside, params, r, into);
  return r;
}

}  // namespace cranioplan
