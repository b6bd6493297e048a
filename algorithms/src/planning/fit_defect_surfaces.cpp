#include "cranioplan/algorithms/planning/fit_defect_surfaces.h"

#include <Eigen/Dense>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <future>
#include <limits>
#include <map>
#include <string>
#include <tuple>

#include "cranioplan/algorithms/geometry/fit_sphere.h"
#include "cranioplan/algorithms/geometry/point_index.h"
#include "cranioplan/algorithms/geometry/surface_locator.h"
#include "cranioplan/algorithms/geometry/surface_samples.h"
#include "cranioplan/model/parallel.h"

namespace cranioplan {
namespace {

constexpr double kReach = 400.0;  // mm: rays from inside the skull leave it well before this

double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
  return v[v.size() / 2];
}

// The least-squares sphere through points[idx] (geometry/fit_sphere.h); none when it does not
// enclose `inside` (the rays' centre) or the points are degenerate.
std::optional<VaultSphere> fit_sphere(const std::vector<Eigen::Vector3d>& points,
                                      const std::vector<size_t>& idx,
                                      const Eigen::Vector3d& inside) {
  const std::optional<FittedSphere> fitted = cranioplan::fit_sphere(points, idx);
  if (!fitted || (fitted->center - inside).norm() >= fitted->radius) return std::nullopt;
  return VaultSphere{fitted->center, fitted->radius};
}

// The ring's band next to the opening (beyond the clearance) that tells the vault's models apart.
constexpr double kNearBandMm = 8.0;

// One ray through the ring's intact bone.
struct Sample {
  Eigen::Vector3d dir;
  double r_out, t;  // outer radius and thickness: original, or original − mirror (guided)
  bool tables_parallel;
};

// Rim-only, the outer radius is fitted either as it is (the spline's quadratic trend keeps the
// ring's curvature) or as its excess over the sphere that fits the ring (the vault keeps
// bending as around the opening): whichever predicts the ring's band next to the opening
// better from the rest of the ring. A quadratic trend sags over wide openings; a sphere bulges
// where the vault flattens; the band tells them apart (docs/decisions/0001-ring-and-fit.md).
// `uv` projects a ray's direction as the fit does; `distance` is each ray's distance from the
// opening.
std::optional<VaultSphere> choose_vault(
    const std::vector<Sample>& ring, const std::vector<Eigen::Vector3d>& outer,
    const std::vector<double>& distance, const Eigen::Vector3d& center,
    const std::function<Eigen::Vector2d(const Eigen::Vector3d&)>& uv, double near_limit_mm,
    const DefectSurfaceParams& params) {
  if (params.vault == DefectSurfaceParams::Vault::Quadratic) return std::nullopt;
  std::vector<size_t> all(ring.size()), far, near;
  for (size_t i = 0; i < ring.size(); ++i) {
    all[i] = i;
    (distance[i] > near_limit_mm ? far : near).push_back(i);
  }
  if (params.vault == DefectSurfaceParams::Vault::Sphere) return fit_sphere(outer, all, center);
  const std::optional<VaultSphere> from_far = fit_sphere(outer, far, center);
  if (!from_far || near.empty()) return std::nullopt;
  std::vector<Eigen::Vector3d> far_pts;
  for (size_t i : far) far_pts.push_back(outer[i]);
  std::vector<size_t> far_sites;
  for (size_t k : thin_points(far_pts, std::max(0.5, params.site_spacing_mm)))
    far_sites.push_back(far[k]);
  // RMS error over the near band of a spline fitted to the far part of the ring.
  auto band_error = [&](const std::optional<VaultSphere>& sphere) {
    auto height = [&](size_t i) {
      return ring[i].r_out - (sphere ? sphere->radius_along(center, ring[i].dir) : 0.0);
    };
    std::vector<Eigen::Vector2d> sites;
    std::vector<double> h;
    for (size_t i : far_sites) {
      sites.push_back(uv(ring[i].dir));
      h.push_back(height(i));
    }
    ThinPlateSpline tps;
    if (!tps.fit(sites, h, std::vector<double>(sites.size(), params.outer_smoothing), 1e-3))
      return std::numeric_limits<double>::infinity();
    double sum = 0.0;
    for (size_t i : near) sum += std::pow(height(i) - tps(uv(ring[i].dir)), 2);
    return std::sqrt(sum / static_cast<double>(near.size()));
  };
  if (band_error(from_far) >= band_error(std::nullopt)) return std::nullopt;
  return fit_sphere(outer, all, center);
}

// Keeps the elements whose flag is set, in order.
template <class T>
void keep_where(std::vector<T>& v, const std::vector<char>& keep) {
  size_t kept = 0;
  for (size_t i = 0; i < v.size(); ++i)
    if (keep[i]) v[kept++] = v[i];
  v.resize(kept);
}

// The ring's outer table points that continue from the rim without a step: reached from a rim
// point (within `rim_reach` radians, as seen from `center`) through neighbouring points
// (within `step` radians) lying at nearly the same distance from the centre (a rise of at most
// twice the distance across, plus a millimetre). Bone much further in or out is other bone
// seen past the vault's edge.
std::vector<char> continuing_from_rim(const std::vector<Eigen::Vector3d>& ring,
                                      const std::vector<Eigen::Vector3d>& rim,
                                      const Eigen::Vector3d& center, double step,
                                      double rim_reach) {
  std::vector<char> reached(ring.size(), 0);
  if (ring.empty()) return reached;
  std::vector<Eigen::Vector3d> dirs;
  for (const auto& p : ring) dirs.push_back((p - center).normalized());
  const PointIndex index(dirs);
  auto continues = [&](const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
    const double ra = (a - center).norm(), rb = (b - center).norm();
    const double cos = (a - center).dot(b - center) / (ra * rb);
    const double across = std::acos(std::clamp(cos, -1.0, 1.0)) * std::min(ra, rb);
    return std::abs(ra - rb) <= 1.0 + 2.0 * across;
  };
  std::vector<int> queue;
  auto reach = [&](const Eigen::Vector3d& from, double within) {
    for (int k : index.within_radius((from - center).normalized(), within))
      if (!reached[k] && continues(from, ring[k])) {
        reached[k] = 1;
        queue.push_back(k);
      }
  };
  for (const auto& p : rim) reach(p, rim_reach);
  while (!queue.empty()) {
    const int i = queue.back();
    queue.pop_back();
    reach(ring[i], step);
  }
  return reached;
}

}  // namespace

Eigen::Vector2d DefectSurfaces::uv(const Eigen::Vector3d& dir) const {
  const double z = dir.dot(axis_);
  return scale_ * Eigen::Vector2d(dir.dot(e1_), dir.dot(e2_)) / z;
}

// The footprint: the ray and this many around it, of which at least kFootprintPaired pass
// through both of the mirror's tables.
constexpr int kFootprintAround = 6;
constexpr int kFootprintPaired = 4;

std::optional<std::pair<double, double>> DefectSurfaces::mirror_along(
    const Eigen::Vector3d& dir) const {
  // Around the ray in the fit's own frame, so that neighbouring rays' footprints are turned
  // alike.
  const Eigen::Vector3d a = unit_across(e1_, dir), b = dir.cross(a);
  // A session's value read as it was written: off when not a number, at most 10 mm.
  const double footprint =
      std::isfinite(mirror_footprint_mm_) ? std::clamp(mirror_footprint_mm_, 0.0, 10.0) : 0.0;
  const double spread = footprint / scale_;
  const int around = spread > 0.0 ? kFootprintAround : 0;
  double r_out = 0.0, t = 0.0;
  int paired = 0;
  for (int k = -1; k < around; ++k) {  // k = -1: the ray itself
    Eigen::Vector3d d = dir;
    if (k >= 0) {
      const double angle = 2.0 * M_PI * k / around;
      d = (dir + spread * (std::cos(angle) * a + std::sin(angle) * b)).normalized();
    }
    const RayThroughBone m =
        cast_through_bone(*mirror_, center_, d, kReach, 0.5, max_thickness_mm_);
    if (!m.paired) continue;
    r_out += (*m.outer - center_).norm();
    t += (*m.outer - *m.inner).norm();
    ++paired;
  }
  if (paired == 0 || (around > 0 && paired < kFootprintPaired)) return std::nullopt;
  return std::make_pair(r_out / paired, t / paired);
}

double VaultSphere::radius_along(const Eigen::Vector3d& from, const Eigen::Vector3d& dir) const {
  // |from + t·dir − center|² = radius²: the far root (`from` lies inside the sphere).
  const Eigen::Vector3d w = from - center;
  const double b = w.dot(dir), c = w.squaredNorm() - radius * radius;
  return -b + std::sqrt(std::max(0.0, b * b - c));
}

std::optional<std::pair<double, double>> DefectSurfaces::radii(const Eigen::Vector3d& dir) const {
  if (!fitted() || dir.dot(axis_) < max_cos_) return std::nullopt;
  const Eigen::Vector2d q = uv(dir);
  double r_out = outer_(q) + (vault_ ? vault_->radius_along(center_, dir) : 0.0), t = thickness_(q);
  if (mirror_) {
    const auto m = mirror_along(dir);
    if (!m) return std::nullopt;
    r_out += m->first;
    t += m->second;
  }
  return std::make_pair(r_out, t);
}

void DefectSurfaces::blend_with(std::shared_ptr<const DefectSurfaces> other, double weight,
                                const std::vector<Eigen::Vector3d>& directions, double taper_mm) {
  blend_ = other && other->fitted() && (other->center_ - center_).norm() < 1e-9 ? std::move(other)
                                                                                : nullptr;
  blend_weight_ = std::clamp(weight, 0.0, 1.0);
  blend_gaps_.reset();
  blend_taper_mm_ = std::max(0.0, taper_mm);
  if (!blend_ || blend_taper_mm_ <= 0.0) return;
  std::vector<Eigen::Vector3d> gaps;
  for (const Eigen::Vector3d& d : directions) {
    const Eigen::Vector3d u = d.normalized();
    if (radii(u) && !blend_->radii(u)) gaps.push_back(u);
  }
  if (!gaps.empty()) blend_gaps_ = std::make_shared<const PointIndex>(std::move(gaps));
}

double DefectSurfaces::blend_taper(const Eigen::Vector3d& dir, double r_out) const {
  if (!blend_gaps_) return 1.0;
  double chord2 = 0.0;
  blend_gaps_->nearest(dir, &chord2);
  const double mm = 2.0 * std::asin(std::min(1.0, 0.5 * std::sqrt(chord2))) * std::abs(r_out);
  const double x = std::clamp(mm / blend_taper_mm_, 0.0, 1.0);
  return x * x * (3.0 - 2.0 * x);  // smoothstep: no kink at either end
}

double DefectSurfaces::blend_share(const Eigen::Vector3d& dir) const {
  const Eigen::Vector3d u = dir.normalized();
  if (!blend_ || blend_weight_ <= 0.0 || !blend_->radii(u)) return 0.0;
  const auto mine = radii(u);
  return mine ? blend_taper(u, mine->first) : 0.0;
}

std::optional<std::pair<Eigen::Vector3d, Eigen::Vector3d>> DefectSurfaces::at(
    const Eigen::Vector3d& dir_in) const {
  const Eigen::Vector3d dir = dir_in.normalized();
  auto mine = radii(dir);
  if (!mine) return std::nullopt;
  auto [r_out, t] = *mine;
  if (blend_) {
    if (const auto theirs = blend_->radii(dir)) {
      const double w = blend_weight_ * blend_taper(dir, r_out);
      r_out += w * (theirs->first - r_out);
      t += w * (theirs->second - t);
    }
  }
  // The bone is at least half a millimetre thick and no thicker than one layer can be.
  const double r_in = r_out - std::clamp(t, 0.5, max_thickness_mm_);
  return std::make_pair(Eigen::Vector3d(center_ + r_out * dir),
                        Eigen::Vector3d(center_ + r_in * dir));
}

// The fit's stages, in order (DefectSurfaces' friend: each sets part of the result).
struct DefectSurfaceFit {
  // The projection around the opening's axis, scaled to the rim's radius, and the cap: the
  // opening's widest angle from its axis plus the ring, capped at 70° (the gnomonic projection
  // stretches without bound towards 90°).
  static void frame(DefectSurfaces& s, const DefectRegion& defect, const SurfaceLocator* mirror,
                    const DefectSurfaceParams& params, const DetectDefectParams& detect) {
    s.center_ = defect.center;
    s.axis_ = defect.axis;
    s.e1_ = across_axis(s.axis_, defect.frame);
    s.e2_ = s.axis_.cross(s.e1_);
    s.mirror_ = mirror;
    s.mirror_guided = mirror != nullptr;
    s.mirror_footprint_mm_ = params.mirror_footprint_mm;
    s.max_thickness_mm_ = detect.max_thickness_mm;
    double rim_radius = 0.0;
    for (const auto& p : defect.outer_rim) rim_radius += (p - s.center_).norm();
    rim_radius /= static_cast<double>(defect.outer_rim.size());
    s.scale_ = rim_radius;
    double hole_cos = 1.0;
    for (const auto& d : defect.hole_directions) hole_cos = std::min(hole_cos, d.dot(s.axis_));
    const double clearance = std::max(0.0, params.rim_clearance_mm);
    const double width = std::max(1.0, params.ring_width_mm);
    const double cap_angle = std::min(
        std::acos(std::clamp(hole_cos, -1.0, 1.0)) + (clearance + width) / rim_radius * 1.2,
        70.0 * M_PI / 180.0);
    s.max_cos_ = std::cos(cap_angle);
  }

  // Rays over the cap, spaced about `ray_spacing_mm` apart at the rim's radius, that cross the
  // intact bone of the ring (between the clearance and the ring's width from the opening):
  // their samples, and the ring's points in `s`.
  static std::vector<Sample> ring(DefectSurfaces& s, const DefectRegion& defect,
                                  const SurfaceLocator& bone, const SurfaceLocator* mirror,
                                  const DefectSurfaceParams& params,
                                  const DetectDefectParams& detect) {
    const double clearance = std::max(0.0, params.rim_clearance_mm);
    const double width = std::max(1.0, params.ring_width_mm);
    const double spacing = std::clamp(params.ray_spacing_mm, 0.5, 10.0) / s.scale_;
    const int n = std::clamp(static_cast<int>(4.0 * M_PI / (spacing * spacing)), 2000, 400000);
    const PointIndex hole(defect.hole_directions);
    std::vector<Sample> ring;
    for (const Eigen::Vector3d& lattice : fibonacci_sphere(n)) {
      const Eigen::Vector3d d = defect.frame * lattice;  // in the skull's frame, as the rim's rays
      if (d.dot(s.axis_) < s.max_cos_) continue;
      const RayThroughBone o = cast_through_bone(bone, s.center_, d, kReach,
                                                 detect.min_thickness_mm, detect.max_thickness_mm);
      if (!o.paired) continue;
      double chord2 = 0.0;
      hole.nearest(d, &chord2);
      const double r_out = (*o.outer - s.center_).norm(), r_in = (*o.inner - s.center_).norm();
      const double dist = 2.0 * std::asin(std::min(1.0, 0.5 * std::sqrt(chord2))) * r_out;
      if (dist < clearance || dist > clearance + width) continue;
      // Near an oblique cut face a ray enters or leaves through the cut instead of a table: its
      // thickness is too small, so it does not inform the thickness (a spline carries it
      // across the opening, and the fitted bone comes out too thin: docs/AUTOPLAN.md, "The ring").
      const bool parallel = params.max_table_angle_deg <= 0 ||
                            -o.inner_normal.dot(o.outer_normal) >=
                                std::cos(params.max_table_angle_deg * M_PI / 180.0);
      if (params.max_outer_tilt_deg > 0 &&
          o.outer_normal.dot(d) < std::cos(params.max_outer_tilt_deg * M_PI / 180.0))
        continue;  // left through a cut face rather than the outer table
      Sample smp{d, r_out, r_out - r_in, parallel};
      if (mirror) {
        const auto m = s.mirror_along(d);
        if (!m) continue;
        smp.r_out -= m->first;
        smp.t -= m->second;
      }
      ring.push_back(smp);
      s.ring_outer.push_back(*o.outer);
      s.ring_inner.push_back(*o.inner);
      s.ring_distance_mm.push_back(dist);
      s.ring_inner_facing.push_back(-o.inner_normal.dot(d));
    }
    return ring;
  }

  // Rim-only, only bone that continues from the rim: past an orbit the rays meet the orbital
  // roof 30-40 mm nearer the centre than the frontal bone, and a ring holding it bends the fitted
  // surfaces and the support markers down to it (a bay in the implant's edge above the orbit:
  // docs/AUTOPLAN.md, "Rim-only"). Mirror-guided, the fit takes the mismatch with the
  // mirror, which meets the same roof on the other side: that bone fits as well as any.
  static void keep_continuing(DefectSurfaces& s, std::vector<Sample>& ring,
                              const DefectRegion& defect, const DefectSurfaceParams& params) {
    const double clearance = std::max(0.0, params.rim_clearance_mm);
    const double spacing = std::clamp(params.ray_spacing_mm, 0.5, 10.0) / s.scale_;
    const std::vector<char> continuing = continuing_from_rim(
        s.ring_outer, defect.outer_rim, s.center_, 1.6 * spacing,
        (clearance + 2.0 * std::clamp(params.ray_spacing_mm, 0.5, 10.0)) / s.scale_);
    keep_where(ring, continuing);
    keep_where(s.ring_outer, continuing);
    keep_where(s.ring_inner, continuing);
    keep_where(s.ring_distance_mm, continuing);
    keep_where(s.ring_inner_facing, continuing);
  }

  // Rim-only, the vault's model (choose_vault); the outer radii then become their excess over it.
  static void vault(DefectSurfaces& s, std::vector<Sample>& ring,
                    const DefectSurfaceParams& params) {
    const double clearance = std::max(0.0, params.rim_clearance_mm);
    s.vault_ = choose_vault(
        ring, s.ring_outer, s.ring_distance_mm, s.center_,
        [&s](const Eigen::Vector3d& d) { return s.uv(d); }, clearance + kNearBandMm, params);
    if (s.vault_)
      for (auto& smp : ring) smp.r_out -= s.vault_->radius_along(s.center_, smp.dir);
  }

  // Fitting sites: the ring's rays averaged over square cells of the site spacing on the
  // fitting plane (uv, millimetres at the rim's radius). Averages, not one ray picked per site:
  // which rays a centre a millimetre away sends through the ring changes, and a spline through
  // single picked rays follows their noise across the opening, where the averages move with the
  // bone, not with the rays (docs/AUTOPLAN.md, "The fit"). The number of sites, 0 when the
  // spline could not be fitted.
  static int fit_sites(const DefectSurfaces& s, ThinPlateSpline& tps, bool outer,
                       const std::vector<Sample>& ring, const std::vector<size_t>& use,
                       const DefectSurfaceParams& params) {
    const double site_spacing = std::max(0.5, params.site_spacing_mm);
    std::map<std::pair<long, long>, std::tuple<Eigen::Vector2d, double, int>> cells;
    for (size_t i : use) {
      const Eigen::Vector2d q = s.uv(ring[i].dir);
      auto& [uv_sum, h_sum, count] = cells[{std::lround(std::floor(q.x() / site_spacing)),
                                            std::lround(std::floor(q.y() / site_spacing))}];
      if (count == 0) uv_sum.setZero();
      uv_sum += q;
      h_sum += outer ? ring[i].r_out : ring[i].t;
      ++count;
    }
    std::vector<Eigen::Vector2d> uv;
    std::vector<double> h;
    std::vector<double> rays;
    for (const auto& [cell, sum] : cells) {
      const auto& [uv_sum, h_sum, count] = sum;
      uv.push_back(uv_sum / count);
      h.push_back(h_sum / count);
      rays.push_back(count);
    }
    const double smoothing = outer && !s.mirror_guided ? params.outer_smoothing : params.smoothing;
    std::vector<double> lambda(uv.size(), std::max(0.0, smoothing));
    // Mirror-guided, a site of fewer rays than the median site is smoothed in proportion.
    if (s.mirror_guided && params.weigh_sites_by_rays && !rays.empty()) {
      const double typical = median(rays);
      for (size_t k = 0; k < rays.size(); ++k) lambda[k] *= std::max(1.0, typical / rays[k]);
    }
    return tps.fit(uv, h, lambda, 1e-3) ? static_cast<int>(uv.size()) : 0;
  }

  // One surface's spline (the outer radius, or the thickness from rays through both tables),
  // with one round of outlier removal, and its residual; the number of sites it was fitted to,
  // 0 when the ring lies on a line. The outer and the inner fit read `s`'s frame and write
  // their own members only, so they may run side by side.
  static int fit(DefectSurfaces& s, bool outer, const std::vector<Sample>& ring,
                 const DefectSurfaceParams& params) {
    std::vector<size_t> all_rays, through_tables;
    for (size_t i = 0; i < ring.size(); ++i) {
      all_rays.push_back(i);
      if (ring[i].tables_parallel) through_tables.push_back(i);
    }
    // Too few rays through both tables (a ring that is all cut faces): the thickness from all.
    const bool thickness_from_all = through_tables.size() < 12;
    const std::vector<size_t>& rays = outer                ? all_rays
                                      : thickness_from_all ? all_rays
                                                           : through_tables;
    auto residual = [&](const ThinPlateSpline& tps, size_t i) {
      return (outer ? ring[i].r_out : ring[i].t) - tps(s.uv(ring[i].dir));
    };
    ThinPlateSpline& tps = outer ? s.outer_ : s.thickness_;
    // The outer radius keeps the ring's curvature across the opening with a quadratic trend.
    // A thickness, and a correction of the mirror, vary gently: an affine trend suffices and
    // stays calm where the ring is open on one side (next to an orbit).
    tps.set_quadratic_trend(outer && !s.mirror_guided);
    int sites = fit_sites(s, tps, outer, ring, rays, params);
    if (sites == 0) return 0;
    // One round of outlier removal: rays far off the first fit.
    std::vector<double> abs_res;
    for (size_t i : rays) abs_res.push_back(std::abs(residual(tps, i)));
    const double limit = std::max(1.0, params.outlier_sigmas * 1.4826 * median(abs_res));
    std::vector<size_t> kept;
    for (size_t i : rays)
      if (std::abs(residual(tps, i)) <= limit) kept.push_back(i);
    if (kept.size() < rays.size() && kept.size() >= 12) {
      const int refit = fit_sites(s, tps, outer, ring, kept, params);
      if (refit > 0) sites = refit;
    }
    // The residual over the ring's rays that the fit describes. Rays farther off than the
    // outlier limit are counted apart: mirror-guided, a ray past an orbit meets the orbital roof
    // on one side and the frontal bone on the other, 30-50 mm apart, and a few of those would
    // make the residual read many times what the rest of the ring fits to (docs/AUTOPLAN.md,
    // "The fit").
    double sum = 0.0;
    size_t count = 0;
    int off = 0;
    for (size_t i = 0; i < ring.size(); ++i)
      if (outer || thickness_from_all || ring[i].tables_parallel) {
        const double e = residual(tps, i);
        if (std::abs(e) > limit) {
          ++off;
          continue;
        }
        sum += e * e;
        ++count;
      }
    (outer ? s.outer_rms_mm : s.thickness_rms_mm) =
        count > 0 ? std::sqrt(sum / static_cast<double>(count)) : 0.0;
    (outer ? s.outer_off_rays : s.thickness_off_rays) = off;
    (outer ? s.outer_off_limit_mm : s.thickness_off_limit_mm) = limit;
    return sites;
  }

  // What was fitted, and how well.
  static std::string describe(const DefectSurfaces& s) {
    char buf[200];
    char model[64];
    if (s.mirror_guided)
      std::snprintf(model, sizeof(model), "mirror corrected");
    else if (s.vault_)
      std::snprintf(model, sizeof(model), "rim only, beyond a %.0f mm sphere", s.vault_->radius);
    else
      std::snprintf(model, sizeof(model), "rim only");
    std::snprintf(buf, sizeof(buf),
                  "surfaces fitted to %d rays of intact bone (%s; residual %.2f mm outer surface, "
                  "%.2f mm thickness",
                  s.ring_rays, model, s.outer_rms_mm, s.thickness_rms_mm);
    std::string message = buf;
    if (s.outer_off_rays > 0 || s.thickness_off_rays > 0) {
      std::snprintf(buf, sizeof(buf), "; %d and %d rays left out, off by over %.1f and %.1f mm",
                    s.outer_off_rays, s.thickness_off_rays, s.outer_off_limit_mm,
                    s.thickness_off_limit_mm);
      message += buf;
    }
    return message + ")";
  }
};

DefectSurfaces fit_defect_surfaces(const DefectRegion& defect, const SurfaceLocator& bone,
                                   const SurfaceLocator* mirror, const DefectSurfaceParams& params,
                                   const DetectDefectParams& detect) {
  DefectSurfaces s;
  if (!defect.found() || defect.hole_directions.empty() || defect.outer_rim.size() < 3) {
    s.message = "no defect to fit surfaces to";
    return s;
  }
  DefectSurfaceFit::frame(s, defect, mirror, params, detect);
  std::vector<Sample> ring = DefectSurfaceFit::ring(s, defect, bone, mirror, params, detect);
  if (!mirror) DefectSurfaceFit::keep_continuing(s, ring, defect, params);
  s.ring_rays = static_cast<int>(ring.size());
  if (ring.size() < 12) {
    s.message = "too little intact bone around the opening to fit its surfaces (" +
                std::to_string(ring.size()) + " rays)";
    return s;
  }
  if (!mirror) DefectSurfaceFit::vault(s, ring, params);
  std::future<int> outer_sites =
      std::async(beside(), [&] { return DefectSurfaceFit::fit(s, true, ring, params); });
  const int inner_sites = DefectSurfaceFit::fit(s, false, ring, params);
  if (outer_sites.get() == 0 || inner_sites == 0) {
    s.message = "the intact bone around the opening lies on a line: no surface can be fitted";
    return s;
  }
  s.sites = inner_sites;
  s.status = DefectSurfaces::Status::Fitted;
  s.message = DefectSurfaceFit::describe(s);
  return s;
}

}  // namespace cranioplan
