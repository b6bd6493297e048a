#include "cranioplan/algorithms/planning/detect_defect.h"

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <functional>
#include <numeric>
#include <optional>
#include <string>

#include "cranioplan/algorithms/geometry/fit_sphere.h"
#include "cranioplan/algorithms/geometry/point_index.h"
#include "cranioplan/algorithms/geometry/surface_locator.h"
#include "cranioplan/algorithms/geometry/surface_samples.h"
#include "cranioplan/algorithms/planning/trace_rim.h"
#include "cranioplan/model/parallel.h"
#include "cranioplan/model/plane.h"

namespace cranioplan {

Eigen::Vector3d across_axis(const Eigen::Vector3d& axis, const Eigen::Matrix3d& frame) {
  constexpr double kNearlyAlong = 0.9539;  // within 17.5° of the axis: its part across is < 0.3
  for (int k = 2; k >= 0; --k)
    if (std::abs(frame.col(k).dot(axis)) < kNearlyAlong) return unit_across(frame.col(k), axis);
  return axis.unitOrthogonal();
}

RayThroughBone cast_through_bone(const SurfaceLocator& locator, const Eigen::Vector3d& center,
                                 const Eigen::Vector3d& dir, double reach, double min_thickness_mm,
                                 double max_thickness_mm) {
  RayThroughBone h;
  const auto in = locator.first_hit(center, center + reach * dir);
  if (!in) return h;
  h.inner = in->point;
  h.inner_normal = locator.face_normal(in->face);
  const auto out = locator.first_hit(center + reach * dir, center);
  if (!out) return h;
  h.outer = out->point;
  h.outer_normal = locator.face_normal(out->face);
  const double t = (*h.outer - *h.inner).norm();
  h.paired = t >= min_thickness_mm && t <= max_thickness_mm;
  return h;
}

namespace {
// A cut's plane lies within 2 mm of the mesh's end (mesh_report): a ray meets it within the
// box widened by a little more along the axes the plane crosses steeply.
constexpr double kBorderSlackMm = 2.5;
}  // namespace

bool ScanBorder::reached_by(const Eigen::Vector3d& from, const Eigen::Vector3d& dir) const {
  const double along = dir.dot(normal);
  if (along <= 1e-9) return false;  // parallel to the plane, or away from it
  const double t = (offset - from.dot(normal)) / along;
  if (t <= 0.0) return false;
  const Eigen::Vector3d hit = from + t * dir;
  // Within the box: along the axes that lie in the plane, exactly; along those the plane
  // crosses steeply (for an axis plane, its normal), within the cut's reach of the mesh's end.
  for (int k = 0; k < 3; ++k) {
    const double slack = std::abs(normal[k]) < 0.5 ? 0.0 : kBorderSlackMm;
    if (hit[k] < box_min[k] - slack || hit[k] > box_max[k] + slack) return false;
  }
  // Within a convex outline counter-clockwise about the normal: left of every edge.
  if (outline.size() < 3) return true;
  for (size_t i = 0; i < outline.size(); ++i) {
    const Eigen::Vector3d& a = outline[i];
    const Eigen::Vector3d& b = outline[(i + 1) % outline.size()];
    if ((b - a).cross(hit - a).dot(normal) < 0.0) return false;
  }
  return true;
}

std::vector<Plane> scan_ends_met(const SkullMesh& implant, const std::vector<ScanBorder>& borders) {
  std::vector<Plane> met;
  for (const ScanBorder& b : borders) {
    int on = 0;
    bool beyond = false;
    for (auto vh : implant.vertices()) {
      const double d = b.normal.dot(to_eigen(implant.point(vh))) - b.offset;
      if (d > kOnScanEndMm + 0.5) beyond = true;
      if (std::abs(d) <= kOnScanEndMm) ++on;
    }
    if (!beyond && on >= kScanEndVertices) met.push_back(Plane{b.normal, b.offset});
  }
  return met;
}

void take_scan_borders(DetectDefectParams& params, const std::optional<MeshReport>& report) {
  if (!params.scan_borders && report) params.scan_borders = scan_borders(*report);
}

std::vector<ScanBorder> scan_borders(const MeshReport& report) {
  std::vector<ScanBorder> out;
  auto add = [&](const std::string& name, const Eigen::Vector3d& outward,
                 const Eigen::Vector3d& in_plane) -> ScanBorder* {
    for (ScanBorder& b : out)
      if (b.side == name) return nullptr;
    ScanBorder& b = out.emplace_back();
    b.side = name;
    b.normal = outward;
    b.offset = outward.dot(in_plane);
    b.box_min = report.bbox_min;
    b.box_max = report.bbox_max;
    return &b;
  };
  // An open cut: reached within the convex outline of all its loops on that side (the bone's
  // cross-section where the scan ended; rays through an opening beside the cut meet its plane
  // beyond the head, as with a cap).
  for (const BoundaryLoop& loop : report.loops)
    if (loop.at_border) add(loop.border, loop.outward, loop.centroid);
  for (ScanBorder& b : out) {
    std::vector<Eigen::Vector3d> corners;
    for (const BoundaryLoop& loop : report.loops)
      if (loop.at_border && loop.border == b.side)
        corners.insert(corners.end(), loop.outline.begin(), loop.outline.end());
    b.outline = hull_in_plane(std::move(corners), b.normal);
  }
  // A closed surface capped where the scan ended: the head's inside is open through the cap's
  // plane as through an open cut, within the cap's own outline (a defect that breaks the cap's
  // ring leaves its outline whole).
  for (const BorderCap& cap : report.caps)
    if (ScanBorder* b = add(cap.border, cap.outward, cap.centroid)) {
      b->box_min = cap.box_min;
      b->box_max = cap.box_max;
      b->outline = cap.outline;
    }
  return out;
}

Eigen::Matrix3d skull_frame(const SkullMesh& skull, const Eigen::Vector3d& center,
                            const Eigen::Vector3d& plane_normal) {
  const Eigen::Vector3d n = plane_normal.normalized();
  Eigen::Matrix2d cov = Eigen::Matrix2d::Zero();
  const Eigen::Vector3d a0 = n.unitOrthogonal(), b0 = n.cross(a0);
  for (auto vh : skull.vertices()) {
    const Eigen::Vector3d d = to_eigen(skull.point(vh)) - center;
    const Eigen::Vector2d q(d.dot(a0), d.dot(b0));
    cov += q * q.transpose();
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eig(cov);
  Eigen::Vector3d a = eig.eigenvectors()(0, 1) * a0 + eig.eigenvectors()(1, 1) * b0;
  Eigen::Vector3d b = n.cross(a);
  double skew_a = 0.0, skew_b = 0.0;
  for (auto vh : skull.vertices()) {
    const Eigen::Vector3d d = to_eigen(skull.point(vh)) - center;
    skew_a += std::pow(d.dot(a), 3);
    skew_b += std::pow(d.dot(b), 3);
  }
  if (skew_a < 0) a = -a;
  if (skew_b < 0) b = -b;
  Eigen::Matrix3d frame;
  frame << a, b, a.cross(b);
  return frame;
}

namespace {

// The least-squares sphere through `points` (fit_sphere), fitted again six times without the
// points more than 2.5 median deviations + 0.5 mm off the last.
std::optional<Eigen::Vector3d> trimmed_sphere(const std::vector<Eigen::Vector3d>& points,
                                              double& radius) {
  std::vector<size_t> kept(points.size());
  std::iota(kept.begin(), kept.end(), size_t{0});
  Eigen::Vector3d c = Eigen::Vector3d::Zero();
  std::vector<double> off(points.size());
  for (int round = 0; round < 6; ++round) {
    const std::optional<FittedSphere> fitted = fit_sphere(points, kept);
    if (!fitted || !(fitted->radius > 0.0)) return std::nullopt;
    c = fitted->center;
    radius = fitted->radius;
    for (size_t i = 0; i < points.size(); ++i) off[i] = std::abs((points[i] - c).norm() - radius);
    std::vector<double> sorted = off;
    std::nth_element(sorted.begin(), sorted.begin() + sorted.size() / 2, sorted.end());
    const double limit = 2.5 * sorted[sorted.size() / 2] + 0.5;
    kept.clear();
    for (size_t i = 0; i < points.size(); ++i)
      if (off[i] < limit) kept.push_back(i);
  }
  return c;
}

}  // namespace

// The vault's regular shell, whose inner table the centre is fitted to: rays through 1.5-15 mm
// of bone. Not DetectDefectParams::max_thickness_mm (20 mm), which lets the rim also cross both
// walls of the frontal sinus; the shell's rays face both tables within 45° anyway.
constexpr double kVaultShellMaxMm = 15.0;

std::optional<Eigen::Vector3d> vault_center(const SurfaceLocator& locator, const Plane& plane,
                                            const Eigen::Vector3d& start, double* radius_mm) {
  const std::vector<Eigen::Vector3d> dirs = fibonacci_sphere(4000);
  Eigen::Vector3d c = plane.project(start);
  double radius = 0.0;
  for (int round = 0; round < 10; ++round) {
    std::vector<std::optional<Eigen::Vector3d>> hit(dirs.size());
    parallel_for(dirs.size(), [&](size_t first, size_t last) {
      for (size_t i = first; i < last; ++i) {
        const RayThroughBone h =
            cast_through_bone(locator, c, dirs[i], 400.0, 1.5, kVaultShellMaxMm);
        if (h.paired && h.outer_normal.dot(dirs[i]) > M_SQRT1_2 &&
            -h.inner_normal.dot(dirs[i]) > M_SQRT1_2)
          hit[i] = h.inner;
      }
    });
    std::vector<Eigen::Vector3d> vault;
    for (const auto& h : hit)
      if (h) vault.push_back(*h);
    if (vault.size() < 100) return std::nullopt;
    const std::optional<Eigen::Vector3d> fitted = trimmed_sphere(vault, radius);
    if (!fitted) return std::nullopt;
    const Eigen::Vector3d next = plane.project(*fitted);
    const double step = (next - c).norm();
    c = next;
    if (step < 0.05) break;
  }
  if (radius_mm) *radius_mm = radius;
  return c;
}

namespace {
// The vault's rays lean one way by at least this (mean of unit directions): a real skull's
// lean well beyond it, a shell closed all round's hardly at all (docs/AUTOPLAN.md, "The skull
// base").
constexpr double kVaultDirected = 0.1;
}  // namespace

std::vector<RimStretch> unseen_rim_stretches(const std::vector<Eigen::Vector3d>& rim,
                                             double min_gap_mm, double times_median) {
  if (rim.size() < 2) return {};
  std::vector<RimStretch> all;
  std::vector<double> lengths;
  for (size_t k = 0; k < rim.size(); ++k) {
    all.push_back({rim[k], rim[(k + 1) % rim.size()]});
    lengths.push_back(all.back().length_mm());
  }
  std::nth_element(lengths.begin(), lengths.begin() + lengths.size() / 2, lengths.end());
  const double limit = std::max(min_gap_mm, times_median * lengths[lengths.size() / 2]);
  std::vector<RimStretch> gaps;
  for (const RimStretch& g : all)
    if (g.length_mm() > limit) gaps.push_back(g);
  std::stable_sort(gaps.begin(), gaps.end(), [](const RimStretch& a, const RimStretch& b) {
    return a.length_mm() > b.length_mm();
  });
  return gaps;
}

namespace {

// Rays from one centre, each cast through the bone.
struct RayCaster {
  const SurfaceLocator& locator;
  Eigen::Vector3d center;
  double reach;
  const DetectDefectParams& params;
  RayThroughBone operator()(const Eigen::Vector3d& d) const {
    return cast_through_bone(locator, center, d, reach, params.min_thickness_mm,
                             params.max_thickness_mm);
  }
};

// The detection's rays and what each met.
struct RayFan {
  std::vector<Eigen::Vector3d> dirs;
  std::vector<std::optional<Eigen::Vector3d>> inner, outer;
  std::vector<char> paired;
  std::vector<std::vector<int>> nbrs;  // neighbours on the sphere (within 1.6 ray spacings)
  Eigen::Vector3d up = Eigen::Vector3d::Zero();
  int size() const { return static_cast<int>(dirs.size()); }
};

// Casts the rays (laid out in `frame`) and finds the vault: rays through a regular shell, both
// tables facing the ray within 45°. The skull base, the face and the orbits are bone met
// obliquely or several times; the vault is the dome above them. The mean direction of these
// rays and of the openings' rays (a defect is vault too) is the skull's superior direction,
// tilted back on a skull with a face (docs/AUTOPLAN.md, "The skull base"); on a shell closed
// all round it is no direction.
RayFan cast_fan(const RayCaster& cast, int n, const Eigen::Matrix3d& frame, bool framed) {
  RayFan fan;
  fan.dirs = fibonacci_sphere(n);
  if (framed)
    for (auto& d : fan.dirs) d = frame * d;
  fan.inner.resize(n);
  fan.outer.resize(n);
  fan.paired.assign(n, 0);
  Eigen::Vector3d vault_sum = Eigen::Vector3d::Zero();
  int vault_rays = 0;
  for (int i = 0; i < n; ++i) {
    const RayThroughBone h = cast(fan.dirs[i]);
    fan.inner[i] = h.inner;
    fan.outer[i] = h.outer;
    fan.paired[i] = h.paired;
    if (!h.inner || (h.paired && h.outer_normal.dot(fan.dirs[i]) > M_SQRT1_2 &&
                     -h.inner_normal.dot(fan.dirs[i]) > M_SQRT1_2)) {
      vault_sum += fan.dirs[i];
      ++vault_rays;
    }
  }
  fan.up = vault_rays > 0 && vault_sum.norm() > kVaultDirected * vault_rays
               ? Eigen::Vector3d(vault_sum.normalized())
               : Eigen::Vector3d::Zero();
  const PointIndex index(fan.dirs);
  const double spacing = std::sqrt(4.0 * M_PI / n);  // radians between neighbouring rays
  fan.nbrs.resize(n);
  for (int i = 0; i < n; ++i)
    for (int j : index.within_radius(fan.dirs[i], 1.6 * spacing))
      if (j != i) fan.nbrs[i].push_back(j);
  return fan;
}

// Connected directions without bone, largest first.
struct Openings {
  std::vector<std::vector<int>> comps;    // the rays of each
  std::vector<int> label;                 // each ray's opening, -1 for none
  std::vector<size_t> order;              // openings by size, largest first
  std::vector<Eigen::Vector3d> mean_dir;  // unit
};

// Openings: connected directions without bone, but for those that leave through the scan's
// border (closed there by the scan's end, not open in the bone).
Openings find_openings(const RayFan& fan, const Eigen::Vector3d& center,
                       const std::vector<ScanBorder>& borders) {
  const int n = fan.size();
  Openings o;
  std::vector<char> blocked(n, 0);
  for (int i = 0; i < n; ++i) {
    blocked[i] = fan.inner[i].has_value();
    for (const ScanBorder& border : borders)
      if (!blocked[i] && border.reached_by(center, fan.dirs[i])) blocked[i] = 1;
  }
  o.label.assign(n, -1);
  for (int i = 0; i < n; ++i) {
    if (blocked[i] || o.label[i] >= 0) continue;
    std::vector<int> comp{i}, stack{i};
    o.label[i] = static_cast<int>(o.comps.size());
    while (!stack.empty()) {
      const int v = stack.back();
      stack.pop_back();
      for (int w : fan.nbrs[v])
        if (!blocked[w] && o.label[w] < 0) {
          o.label[w] = o.label[i];
          comp.push_back(w);
          stack.push_back(w);
        }
    }
    o.comps.push_back(std::move(comp));
  }
  o.order.resize(o.comps.size());
  std::iota(o.order.begin(), o.order.end(), 0);
  std::sort(o.order.begin(), o.order.end(),
            [&](size_t a, size_t b) { return o.comps[a].size() > o.comps[b].size(); });
  o.mean_dir.assign(o.comps.size(), Eigen::Vector3d::Zero());
  for (size_t c = 0; c < o.comps.size(); ++c) {
    for (int i : o.comps[c]) o.mean_dir[c] += fan.dirs[i];
    o.mean_dir[c].normalize();
  }
  return o;
}

// The skull base (or the scan's cut): the rank (in `o.order`) of the largest opening whose mean
// direction points away from the vault, more than 105° from its direction; o.order.size() for
// none. Seen from the rays' start (detect_defect_near_plane) a skull's foramen magnum lies well
// beyond that limit and its defect within it, on coarse copies of the skull too (seen from the
// vertex centroid the angles shift as the thin bone around the openings opens up on a coarse
// copy). The orbits lie further still but are smaller than the foramen; a
// limit too near the foramen's angle can miss the foramen on a coarse copy, take an orbit for
// the base and plan the foramen magnum as the defect (the angles measured: docs/AUTOPLAN.md,
// "The skull base"). Where the surface is open along a cut that faces away from the vault
// (`borders`), the base must face it too (its mean direction within 60° of the cut's outward
// normal): the cut blocks the base's own rays, and a defect seen far from the vault is then
// not taken for the base. With the skull's frame (its third axis the midsagittal plane's normal),
// the base must also lie within 30° of the plane, as the foramen magnum and a scan's cut do: a
// large one-sided defect low on the side of the head (a decompressive hemicraniectomy,
// 8,000 mm² and more) is larger than the foramen magnum and would otherwise be taken for the
// base if it reached 105°. Without such an opening, or without a vault direction, the skull is
// closed below.
size_t skull_base(const Openings& o, const Eigen::Vector3d& up, const Eigen::Matrix3d& frame,
                  bool framed, const std::vector<ScanBorder>& borders) {
  constexpr double kBaseAwayFromVault = -0.2588;  // cos 105°
  constexpr double kBaseNearMidline = 0.5;        // sin 30°
  constexpr double kTowardsCut = 0.5;             // cos 60°
  std::vector<Eigen::Vector3d> cuts_below;
  for (const ScanBorder& b : borders)
    if (b.normal.dot(up) < -kTowardsCut) cuts_below.push_back(b.normal);
  for (size_t r = 0; r < o.order.size() && up.norm() > 0; ++r) {
    const Eigen::Vector3d& mean = o.mean_dir[o.order[r]];
    const bool near_midline = !framed || std::abs(mean.dot(frame.col(2))) < kBaseNearMidline;
    bool towards_cut = cuts_below.empty();
    for (const Eigen::Vector3d& n : cuts_below)
      towards_cut = towards_cut || mean.dot(n) > kTowardsCut;
    if (mean.dot(up) < kBaseAwayFromVault && near_midline && towards_cut) return r;
  }
  return o.order.size();
}

// An opening large enough to be a defect: its rank in Openings::order, its rim (bone rays next
// to it) and its area at the radius of the rim.
struct Candidate {
  size_t r;
  std::vector<int> rim;
  double area;
};

// The openings large enough to be defects but the base, largest first; with a point given, the
// one holding the ray nearest that point's direction first.
std::vector<Candidate> defect_candidates(const RayFan& fan, const Openings& o, size_t base,
                                         const Eigen::Vector3d& center,
                                         const DetectDefectParams& params) {
  std::vector<Candidate> candidates;
  for (size_t r = 0; r < o.order.size(); ++r) {
    if (r == base) continue;
    const std::vector<int>& comp = o.comps[o.order[r]];
    std::vector<int> rim;
    for (int i : comp)
      for (int j : fan.nbrs[i])
        if (fan.paired[j]) rim.push_back(j);
    std::sort(rim.begin(), rim.end());
    rim.erase(std::unique(rim.begin(), rim.end()), rim.end());
    if (rim.empty()) continue;
    double radius = 0.0;
    for (int j : rim) radius += (*fan.outer[j] - center).norm();
    radius /= static_cast<double>(rim.size());
    const double area =
        static_cast<double>(comp.size()) * 4.0 * M_PI / fan.size() * radius * radius;
    if (area < params.min_area_mm2) break;  // sorted by size: the rest are smaller
    candidates.push_back({r, std::move(rim), area});
  }
  if (params.near && candidates.size() > 1 && (*params.near - center).norm() > 1e-9) {
    const Eigen::Vector3d want = (*params.near - center).normalized();
    auto closeness = [&](const Candidate& c) {
      double best = -2.0;
      for (int i : o.comps[o.order[c.r]]) best = std::max(best, fan.dirs[i].dot(want));
      return best;
    };
    std::stable_sort(
        candidates.begin(), candidates.end(),
        [&](const Candidate& a, const Candidate& b) { return closeness(a) > closeness(b); });
  }
  return candidates;
}

// A ray through an opening: the one nearest its mean direction (the mean itself may fall outside
// an opening that is not convex, even into another), so that a caller can plan it with a point
// along it.
Eigen::Vector3d ray_through(const RayFan& fan, const Openings& o, const Candidate& c) {
  const std::vector<int>& comp = o.comps[o.order[c.r]];
  const Eigen::Vector3d& mean = o.mean_dir[o.order[c.r]];
  int through = comp.front();
  for (int i : comp)
    if (fan.dirs[i].dot(mean) > fan.dirs[through].dot(mean)) through = i;
  return fan.dirs[through];
}

// The rim of the opening `c`, in order around `region.axis`: in each angular sector the rim ray
// nearest the axis (the innermost bone), so the rim is a simple loop even where the ray grid is
// ragged; each refined towards its nearest opening ray by bisection, so the rim sits where the
// bone ends rather than up to a ray spacing inside it (rays must still cross bone of a
// plausible thickness on both tables: they share the ray).
void trace_rim(const RayFan& fan, const Openings& o, const Candidate& c, const RayCaster& cast,
               DefectRegion& region) {
  const std::vector<int>& rim = c.rim;
  const Eigen::Vector3d e1 = across_axis(region.axis, region.frame), e2 = region.axis.cross(e1);
  const int sectors = std::clamp(static_cast<int>(rim.size()) / 2, 8, 360);
  std::vector<int> best(sectors, -1);
  for (int j : rim) {
    const double a = std::atan2(fan.dirs[j].dot(e2), fan.dirs[j].dot(e1));
    const int sct = std::clamp(static_cast<int>((a + M_PI) / (2 * M_PI) * sectors), 0, sectors - 1);
    if (best[sct] < 0 || fan.dirs[j].dot(region.axis) > fan.dirs[best[sct]].dot(region.axis))
      best[sct] = j;
  }
  for (int j : best) {
    if (j < 0) continue;
    Eigen::Vector3d in_pt = *fan.inner[j], out_pt = *fan.outer[j];
    int open_nbr = -1;
    for (int w : fan.nbrs[j])
      if (o.label[w] == static_cast<int>(o.order[c.r]) &&
          (open_nbr < 0 || fan.dirs[w].dot(fan.dirs[j]) > fan.dirs[open_nbr].dot(fan.dirs[j])))
        open_nbr = w;
    if (open_nbr >= 0) {
      Eigen::Vector3d bone_dir = fan.dirs[j], open_dir = fan.dirs[open_nbr];
      for (int it = 0; it < 6; ++it) {
        const Eigen::Vector3d mid = (bone_dir + open_dir).normalized();
        const RayThroughBone h = cast(mid);
        if (h.paired) {
          bone_dir = mid;
          in_pt = *h.inner;
          out_pt = *h.outer;
        } else {
          open_dir = mid;
        }
      }
    }
    region.outer_rim.push_back(out_pt);
    region.inner_rim.push_back(in_pt);
  }
  // Refinement moves rays sideways a little: restore the angular order around the axis.
  std::vector<size_t> by_angle(region.outer_rim.size());
  std::iota(by_angle.begin(), by_angle.end(), 0);
  auto polar = [&](const Eigen::Vector3d& p) {
    const Eigen::Vector3d d = p - region.center;
    return std::atan2(d.dot(e2), d.dot(e1));
  };
  std::sort(by_angle.begin(), by_angle.end(), [&](size_t a, size_t b) {
    return polar(region.outer_rim[a]) < polar(region.outer_rim[b]);
  });
  std::vector<Eigen::Vector3d> sorted_outer, sorted_inner;
  for (size_t k : by_angle) {
    sorted_outer.push_back(region.outer_rim[k]);
    sorted_inner.push_back(region.inner_rim[k]);
  }
  region.outer_rim = std::move(sorted_outer);
  region.inner_rim = std::move(sorted_inner);
}

// Runs of consecutive points flagged in `flags` (a closed loop), each as a stretch from its first
// to its last point.
std::vector<RimStretch> flagged_stretches(const std::vector<Eigen::Vector3d>& loop,
                                          const std::vector<char>& flags) {
  std::vector<RimStretch> out;
  const size_t n = loop.size();
  if (n == 0) return out;
  size_t start = 0;
  while (start < n && flags[start]) ++start;
  if (start == n) return {{loop.front(), loop.back()}};  // all of it
  for (size_t k = 1; k <= n; ++k) {
    const size_t i = (start + k) % n;
    if (!flags[i] || flags[(i + n - 1) % n]) continue;
    size_t j = i;
    while (flags[(j + 1) % n] && (j + 1) % n != i) j = (j + 1) % n;
    out.push_back({loop[i], loop[j]});
  }
  return out;
}

// The rim traced on the bone from the faces next to the opening the rays saw (its rim rays and
// their bone neighbours); when it is found, the region's rim, opening and axis are the traced
// ones, and stretches along the scan's end are named.
// A stretch of the traced rim along the scan's end shorter than this is not the opening running
// into the scan's end, mm.
constexpr double kMinAtBorderMm = 5.0;
// Bone a ray inside the traced rim meets more than this nearer the centre than the rim is seen
// through the opening, mm.
constexpr double kInsideRimMm = 10.0;
// How far the outer table a seed of the traced rim lies on may be from the rays' median, mm.
constexpr double kSeedRadiusMm = 15.0;

// How many steps over the rays' neighbours (about 1.6° each) the band reaches into rays closed
// by the scan's end next to the opening.
constexpr int kBandRings = 8;

void trace_on_bone(const SkullMesh& skull, const SurfaceLocator& locator, const RayFan& fan,
                   const std::vector<int>& comp, const Candidate& c, const RayCaster& cast,
                   const std::vector<ScanBorder>& borders, bool runs_into_scan_end,
                   DefectRegion& region) {
  std::vector<int> near = c.rim;
  for (int j : c.rim)
    for (int w : fan.nbrs[j])
      if (fan.paired[w]) near.push_back(w);
  std::sort(near.begin(), near.end());
  near.erase(std::unique(near.begin(), near.end()), near.end());
  // The tables are grown from the vault's regular shell only: both tables facing the ray
  // within 45°, and the outer table within kSeedRadiusMm of the rays' median distance to it. A
  // ray next to the opening that met other bone seen through it (a ridge of the skull base, deep
  // in the head) would seed that bone's face as the outer table.
  std::vector<RayThroughBone> hits;
  std::vector<double> radii;
  for (int j : near) {
    hits.push_back(cast(fan.dirs[j]));
    if (hits.back().paired) radii.push_back((*hits.back().outer - region.center).norm());
  }
  if (radii.empty()) return;
  std::nth_element(radii.begin(), radii.begin() + radii.size() / 2, radii.end());
  const double typical = radii[radii.size() / 2];
  std::vector<Eigen::Vector3d> outer_seeds, inner_seeds;
  for (size_t k = 0; k < near.size(); ++k) {
    const RayThroughBone& h = hits[k];
    const Eigen::Vector3d& d = fan.dirs[near[k]];
    if (!h.paired || h.outer_normal.dot(d) < M_SQRT1_2 || -h.inner_normal.dot(d) < M_SQRT1_2 ||
        std::abs((*h.outer - region.center).norm() - typical) > kSeedRadiusMm)
      continue;
    outer_seeds.push_back(*h.outer);
    inner_seeds.push_back(*h.inner);
  }
  const Eigen::Vector3d e1 = across_axis(region.axis, region.frame);
  // The band the tables are traced over: around the opening's rays and the rays next to them
  // that meet no bone, closed by the scan's end (where the opening runs into it, its edge goes
  // on along the scan's border).
  std::vector<Eigen::Vector3d> band = region.hole_directions;
  std::vector<int> ring(fan.size(), -1);  // steps from the opening's rays
  std::vector<int> front = comp;
  for (int i : comp) ring[i] = 0;
  for (size_t q = 0; q < front.size(); ++q) {
    if (ring[front[q]] >= kBandRings) continue;
    for (int w : fan.nbrs[front[q]])
      if (ring[w] < 0 && !fan.inner[w]) {
        ring[w] = ring[front[q]] + 1;
        band.push_back(fan.dirs[w]);
        front.push_back(w);
      }
  }
  TraceRimParams trace;
  trace.along_scan_end = runs_into_scan_end;
  const TracedRim traced =
      trace_rim_on_bone(skull, locator, region.center, region.axis, e1, band, region.outer_rim,
                        region.inner_rim, outer_seeds, inner_seeds, borders, trace);
  if (!traced.traced()) return;
  const std::vector<char> inside =
      inside_loop(fan.dirs, traced.outer, region.center, region.axis, e1);
  // The opening: the rays inside the traced rim, but for those that meet bone about as far out
  // as the rim (the wedge of an oblique cut face, inside its outer corner). Bone met well
  // inside the rim is seen through the opening (the floor of a fossa below a flap's lower
  // edge).
  const Eigen::Vector3d e2 = region.axis.cross(e1);
  std::vector<std::pair<double, double>> rim_by_bearing;  // (bearing, distance from the centre)
  for (const Eigen::Vector3d& p : traced.outer) {
    const Eigen::Vector3d d = p - region.center;
    rim_by_bearing.emplace_back(std::atan2(d.dot(e2), d.dot(e1)), d.norm());
  }
  std::sort(rim_by_bearing.begin(), rim_by_bearing.end());
  auto rim_radius = [&](const Eigen::Vector3d& dir) {
    const double b = std::atan2(dir.dot(e2), dir.dot(e1));
    auto it =
        std::lower_bound(rim_by_bearing.begin(), rim_by_bearing.end(), std::make_pair(b, -1.0));
    if (it == rim_by_bearing.end()) it = rim_by_bearing.begin();
    return it->second;
  };
  std::vector<Eigen::Vector3d> holes;
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  size_t count = 0;
  for (int i = 0; i < fan.size(); ++i) {
    if (!inside[i]) continue;
    if (fan.outer[i] &&
        (*fan.outer[i] - region.center).norm() >= rim_radius(fan.dirs[i]) - kInsideRimMm)
      continue;
    holes.push_back(fan.dirs[i]);
    sum += fan.dirs[i];
    ++count;
  }
  if (holes.empty() || sum.norm() < 1e-9) return;
  double radius = 0.0;
  for (const Eigen::Vector3d& p : traced.outer) radius += (p - region.center).norm();
  radius /= static_cast<double>(traced.outer.size());
  region.hole_directions = std::move(holes);
  region.axis = sum.normalized();
  region.area_mm2 = static_cast<double>(count) * 4.0 * M_PI / fan.size() * radius * radius;
  region.outer_rim = traced.outer;
  if (traced.inner.size() == traced.outer.size()) {
    region.inner_rim = traced.inner;
  } else {  // the inner table not traced: the rays' inner rim nearest each point
    const std::vector<Eigen::Vector3d> seen = region.inner_rim, seen_outer = region.outer_rim;
    region.inner_rim.clear();
    for (const Eigen::Vector3d& p : traced.outer) {
      size_t best = 0;
      for (size_t k = 1; k < seen_outer.size(); ++k)
        if ((seen_outer[k] - p).squaredNorm() < (seen_outer[best] - p).squaredNorm()) best = k;
      region.inner_rim.push_back(seen[best]);
    }
  }
  region.rim_traced = true;
  // Stretches along the scan's end, of kMinAtBorderMm or more (a point of the rim that touches a
  // cap where the bone's edge meets the scan's is not the opening running into it).
  for (const RimStretch& st : flagged_stretches(traced.outer, traced.at_scan_border))
    if (st.length_mm() >= kMinAtBorderMm) region.at_scan_border.push_back(st);
  for (const ScanBorder& b : borders)
    for (const RimStretch& st : region.at_scan_border)
      if (std::abs(b.normal.dot(st.from) - b.offset) < 2.0 &&
          std::abs(b.normal.dot(st.to) - b.offset) < 2.0) {
        region.scan_ends.push_back(Plane{b.normal, b.offset});
        break;
      }
}

// Rays of the opening next to this many rays closed by the scan's end (neighbours within 1.6
// ray spacings; 1.4° apart at the default 20,000 rays) make it an opening that runs into the
// scan's end, not one that only touches it at a corner.
constexpr int kScanEndRays = 8;

// Whether the opening `comp` runs into the scan's end: rays next to it meet no bone and reach
// a border within its outline.
bool reaches_scan_end(const RayFan& fan, const std::vector<int>& comp,
                      const Eigen::Vector3d& center, const std::vector<ScanBorder>& borders) {
  if (borders.empty()) return false;
  std::vector<char> counted(fan.size(), 0);
  int closed = 0;
  for (int i : comp)
    for (int w : fan.nbrs[i]) {
      if (counted[w] || fan.inner[w]) continue;
      counted[w] = 1;
      for (const ScanBorder& b : borders)
        if (b.reached_by(center, fan.dirs[w])) {
          if (++closed >= kScanEndRays) return true;
          break;
        }
    }
  return false;
}

// Whether the opening's rim is traced on the bone (DetectDefectParams::trace_from_area_mm2):
// large, seen by the rays with a long stretch of its rim unseen, or running into the scan's end
// (where no ray sees a rim, and the traced one follows the border's plane).
bool wants_trace(const DefectRegion& region, const DetectDefectParams& params,
                 bool runs_into_scan_end) {
  if (region.area_mm2 >= params.trace_from_area_mm2 || runs_into_scan_end) return true;
  const std::vector<RimStretch> unseen = unseen_rim_stretches(region.outer_rim);
  return !unseen.empty() && unseen.front().length_mm() >= params.trace_from_unseen_mm;
}

}  // namespace

DefectRegion detect_defect(const SkullMesh& skull, const SurfaceLocator& locator,
                           const Eigen::Vector3d& center, const DetectDefectParams& params) {
  const auto t0 = std::chrono::steady_clock::now();
  DefectRegion region;
  region.center = center;
  double reach = 0.0;
  for (auto vh : skull.vertices())
    reach = std::max(reach, (to_eigen(skull.point(vh)) - center).norm());
  reach += 10.0;
  if (params.frame) region.frame = *params.frame;
  const RayCaster cast{locator, center, reach, params};
  const RayFan fan = cast_fan(cast, std::clamp(params.directions, 2000, 200000), region.frame,
                              params.frame.has_value());
  region.up = fan.up;
  static const std::vector<ScanBorder> kNoBorder;
  const std::vector<ScanBorder>& borders = params.scan_borders ? *params.scan_borders : kNoBorder;
  const Openings openings = find_openings(fan, center, borders);
  const size_t base =
      skull_base(openings, region.up, region.frame, params.frame.has_value(), borders);
  // The defect is the largest of the others whose area, at the radius of its rim, is large
  // enough (or the one towards a point given); the rest are named by a ray through each.
  const std::vector<Candidate> candidates = defect_candidates(fan, openings, base, center, params);
  for (size_t k = 1; k < candidates.size(); ++k)
    region.other_axes.push_back(ray_through(fan, openings, candidates[k]));
  if (!candidates.empty()) {
    const Candidate& chosen = candidates.front();
    const std::vector<int>& comp = openings.comps[openings.order[chosen.r]];
    region.status = DefectRegion::Status::Found;
    region.other_openings = static_cast<int>(candidates.size()) - 1;
    region.area_mm2 = chosen.area;
    for (int i : comp) region.hole_directions.push_back(fan.dirs[i]);
    region.axis = openings.mean_dir[openings.order[chosen.r]];
    trace_rim(fan, openings, chosen, cast, region);
    const bool runs_into_scan_end = reaches_scan_end(fan, comp, center, borders);
    if (params.trace_rim_on_bone && wants_trace(region, params, runs_into_scan_end))
      trace_on_bone(skull, locator, fan, comp, chosen, cast, borders, runs_into_scan_end, region);
    // Asked for the opening towards a point, and none lies that way: the nearest was planned,
    // and the message says so (a point on intact bone, or at a cut that did not go through,
    // would otherwise plan another opening without a word).
    if (params.near && (*params.near - center).norm() > 1e-9) {
      const Eigen::Vector3d want = (*params.near - center).normalized();
      double closest = -1.0;
      for (int i : comp) closest = std::max(closest, fan.dirs[i].dot(want));
      region.near_miss_deg = std::acos(std::clamp(closest, -1.0, 1.0)) * 180.0 / M_PI;
    }
    if (!region.rim_traced) region.unseen_rim = unseen_rim_stretches(region.outer_rim);
  }
  region.message = region.describe();
  region.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return region;
}

std::string DefectRegion::describe(bool others_planned) const {
  if (!found()) return "no defect found (no opening in the skull besides its base)";
  std::string text =
      "opening of " + std::to_string(static_cast<long long>(area_mm2)) + " mm² found";
  if (other_openings > 0)
    text += " (" + std::to_string(other_openings) +
            (other_openings == 1 ? " other opening" : " other openings") +
            (others_planned ? ", planned as well)"
                            : " not planned: choose with a point near the defect)");
  if (near_miss_deg > kNearMissDeg)
    text += "; no opening lies towards the point given: the nearest, planned, is " +
            std::to_string(std::lround(near_miss_deg)) + "° from it";
  if (!unseen_rim.empty()) {
    std::string lengths;
    for (size_t k = 0; k < unseen_rim.size(); ++k)
      lengths += (k == 0                       ? ""
                  : k + 1 == unseen_rim.size() ? " and "
                                               : ", ") +
                 std::to_string(static_cast<long long>(std::lround(unseen_rim[k].length_mm())));
    text += "; rim not seen along " + lengths +
            " mm (rays graze the bone there): check the edge markers";
  }
  if (!at_scan_border.empty()) {
    double along = 0.0;
    for (const RimStretch& s : at_scan_border) along += s.length_mm();
    text += "; the opening reaches the scan's border (along " + std::to_string(std::lround(along)) +
            " mm): the bone beyond the scan is unknown, and the implant ends there";
  }
  return text;
}

}  // namespace cranioplan
