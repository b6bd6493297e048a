#include "cranioplan/algorithms/implant/fixation_tabs.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cassert>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <optional>
#include <vector>

#include "cranioplan/algorithms/geometry/mesh_distance_field.h"
#include "cranioplan/algorithms/geometry/surface_locator.h"
#include "cranioplan/algorithms/geometry/voxelize_mesh.h"
#include "cranioplan/algorithms/io/extract_bone_surface.h"
#include "cranioplan/model/parallel.h"

namespace cranioplan {

namespace {

// A tab's underside keeps this far off the bone (the quality report's overlap grid then counts
// none of it inside the bone), mm.
constexpr double kUndersideMm = 0.05;
// How far a tab reaches back over the implant from its edge (its inner end is straight), mm.
constexpr double kOverlapMm = 3.0;
// Into the gap between the implant's edge and the bone, the tab reaches this deep below the
// bone's outer surface at its edge, mm.
constexpr double kPlugMm = 1.5;
// Narrower gaps under a tab than twice this radius are bridged at most this deep, mm.
constexpr double kCrackRadiusMm = 0.6, kCrackDepthMm = 0.3;
// Over the implant a tab's underside comes down onto the implant where it lies up to the first
// below the bridged underside, not where the second or more, mm.
constexpr double kFillFullMm = 1.0, kFillNoneMm = 2.0;
// The tab's top edges are rounded over this radius, mm.
constexpr double kEdgeRoundMm = 1.5;
// The even placement spaces tabs by one per this much rim, mm.
constexpr double kRimPerTabMm = 40.0;
// The even placement places a tab again when it stands off the bone by more than this (the
// quality report's default limit, QualityParams::max_tab_gap_mm), mm, at most this many times.
constexpr double kRestsWithinMm = 0.2;
constexpr int kPlacementRounds = 3;
// The rim is sampled in this many sectors around the direction from the skull's inside to the
// implant's centre.
constexpr int kSectors = 360;

// How deep the 90° countersink reaches into the tab, mm.
double countersink_depth(const TabParams& p) {
  return p.countersink_diameter_mm > 0.0 ? 0.5 * (p.countersink_diameter_mm - p.screw_diameter_mm)
                                         : 0.0;
}

// The distance along the tab's axis of its screws' centres from its edge, the outermost first.
std::vector<double> screw_positions(const TabParams& p) {
  std::vector<double> at{p.length_mm - 0.5 * p.width_mm};
  if (p.screws == 2) at.push_back(at[0] - p.width_mm);  // the ring between as at the sides
  return at;
}

// The implant's outer edge as seen from inside the skull, the way the implant was built: along
// rays from the inside point, in each of kSectors sectors around the direction of the implant's
// centre, leaning out from that direction in steps of 0.25° for as long as the ray's outermost
// hit is on the implant (not on bone beyond it, and not missing it): the last such hit.
struct Rim {
  std::vector<Eigen::Vector3d> points;  // in angular order around the centre direction
  std::vector<double> arc;              // arc length at each point, mm
  double length = 0.0;
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
};

Rim trace_rim(const SurfaceLocator& self, const SkullMesh& implant, const SurfaceLocator& bone,
              const Eigen::Vector3d& inside) {
  Rim rim;
  rim.centre = vertex_centroid(implant);
  const Eigen::Vector3d axis = (rim.centre - inside).normalized();
  const Eigen::Vector3d e1 = axis.unitOrthogonal(), e2 = axis.cross(e1);
  std::vector<Eigen::Vector3d> edge(kSectors);
  std::vector<uint8_t> found(kSectors, 0);
  parallel_for(
      kSectors,
      [&](size_t begin, size_t end) {
        for (size_t s = begin; s < end; ++s) {
          const double theta = 2.0 * M_PI * static_cast<double>(s) / kSectors;
          const Eigen::Vector3d across = std::cos(theta) * e1 + std::sin(theta) * e2;
          // The implant's outermost hit along the ray leaning `phi` degrees out, when nothing
          // lies beyond it and it is on the outer surface (facing within 60° of away from the
          // inside: a ray past the edge meets the side wall).
          const auto implant_at = [&](double phi) -> std::optional<Eigen::Vector3d> {
            const double a = phi * M_PI / 180.0;
            const Eigen::Vector3d d = std::cos(a) * axis + std::sin(a) * across;
            const Eigen::Vector3d far = inside + 500.0 * d;
            const auto on_implant = self.first_hit(far, inside);
            if (!on_implant) return std::nullopt;
            const auto on_bone = bone.first_hit(far, inside);
            if (on_bone && on_bone->distance < on_implant->distance - 0.5) return std::nullopt;
            if (self.face_normal(on_implant->face).dot(d) < 0.5) return std::nullopt;
            return on_implant->point;
          };
          double inner = -1.0, outer = 89.0;
          for (double phi = 0.0; phi < 89.0; phi += 0.25) {
            const auto hit = implant_at(phi);
            if (!hit) {
              outer = phi;
              break;
            }
            edge[s] = *hit;
            inner = phi;
          }
          if (inner < 0.0) continue;
          found[s] = 1;
          for (int k = 0; k < 10; ++k) {  // the edge to 0.25°/1024 by bisection
            const double mid = 0.5 * (inner + outer);
            if (const auto hit = implant_at(mid)) {
              edge[s] = *hit;
              inner = mid;
            } else {
              outer = mid;
            }
          }
        }
      },
      8);
  for (int s = 0; s < kSectors; ++s)
    if (found[s]) rim.points.push_back(edge[s]);
  // Arc length along the rim averaged over five sectors: the edge of an implant meshed from
  // voxels zigzags by a fraction of a voxel, which would add a fifth to its length.
  const size_t n = rim.points.size();
  std::vector<Eigen::Vector3d> smooth(n);
  for (size_t i = 0; i < n; ++i) {
    smooth[i] = Eigen::Vector3d::Zero();
    for (size_t k = 0; k < 5; ++k) smooth[i] += rim.points[(i + n + k - 2) % n];
    smooth[i] /= 5.0;
  }
  rim.arc.assign(n, 0.0);
  for (size_t i = 1; i < n; ++i) rim.arc[i] = rim.arc[i - 1] + (smooth[i] - smooth[i - 1]).norm();
  if (n > 1) rim.length = rim.arc.back() + (smooth.front() - smooth.back()).norm();
  return rim;
}

// A tab leaving the rim at sample `i`, or why none can be made there.
struct Candidate {
  Tab tab;
  std::string problem;  // empty: it rests on bone
  // The bone's outer surface under the tab at its highest, along its normal from the rim
  // point, mm.
  double bone_high = 0.0;
  // The bone's outer table next to the implant's edge (the lowest of three lines along the tab),
  // and the implant's outer surface under the tab's inner end (the highest), along the normal.
  double edge_height = 0.0, implant_high = 0.0;
  double bone_turn_deg = 0.0;  // the largest angle between the bone's faces there and its normal
};

// The bone's outer normal under a tab at rim point r (u outward, v along the rim, n0 the
// radial direction): the mean of its faces' under four points of the tab; none where fewer
// than three of them meet bone.
std::optional<Eigen::Vector3d> bone_normal_under(const SurfaceLocator& bone,
                                                 const Eigen::Vector3d& r, const Eigen::Vector3d& u,
                                                 const Eigen::Vector3d& v,
                                                 const Eigen::Vector3d& n0, const TabParams& p) {
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();
  int hits = 0;
  for (const Eigen::Vector2d& ab : {Eigen::Vector2d(0.4 * p.length_mm, -0.25 * p.width_mm),
                                    Eigen::Vector2d(0.4 * p.length_mm, 0.25 * p.width_mm),
                                    Eigen::Vector2d(p.length_mm - 0.25 * p.width_mm, 0.0),
                                    Eigen::Vector2d(0.7 * p.length_mm, 0.0)}) {
    const Eigen::Vector3d m = r + ab.x() * u + ab.y() * v;
    const auto hit = bone.first_hit(m + 8.0 * n0, m - 8.0 * n0);
    if (!hit) continue;
    Eigen::Vector3d f = bone.face_normal(hit->face);
    if (f.dot(n0) < 0) f = -f;
    normal += f;
    ++hits;
  }
  if (hits < 3 || normal.norm() == 0) return std::nullopt;
  return normal.normalized();
}

// The nearest of a tab's outline and screws to the midsagittal plane (0 when it straddles it);
// v: across the tab.
double midline_distance(const Plane& midline, const Tab& tab, const Eigen::Vector3d& v) {
  double lo = 1e9, hi = -1e9;
  auto see = [&](const Eigen::Vector3d& x) {
    const double d = midline.signed_distance(x);
    lo = std::min(lo, d);
    hi = std::max(hi, d);
  };
  for (const double at : {0.0, 0.5 * tab.length_mm, tab.length_mm})
    for (const double across : {-0.5, 0.0, 0.5})
      see(tab.rim + at * tab.outward + across * tab.width_mm * v);
  for (const Hole& s : tab.screws) see(s.center);
  return lo <= 0.0 && hi >= 0.0 ? 0.0 : std::min(std::abs(lo), std::abs(hi));
}

Candidate make_tab(const Rim& rim, size_t i, const SurfaceLocator& self, const SurfaceLocator& bone,
                   const Eigen::Vector3d& inside, const TabParams& p) {
  Candidate out;
  Tab& tab = out.tab;
  const size_t n = rim.points.size();
  const Eigen::Vector3d r = rim.points[i];
  // The rim's direction over about 3 mm to either side.
  size_t a = i, b = i;
  for (int step = 0; step < static_cast<int>(n) / 4; ++step) {
    if ((rim.points[a] - r).norm() >= 3.0 && (rim.points[b] - r).norm() >= 3.0) break;
    if ((rim.points[a] - r).norm() < 3.0) a = (a + n - 1) % n;
    if ((rim.points[b] - r).norm() < 3.0) b = (b + 1) % n;
  }
  const Eigen::Vector3d along = rim.points[b] - rim.points[a];
  const Eigen::Vector3d n0 = (r - inside).normalized();
  const Eigen::Vector3d away = unit_across(r - rim.centre, n0);
  auto frame = [&](const Eigen::Vector3d& normal) {
    Eigen::Vector3d u =
        along.norm() > 0 ? unit_across(normal.cross(along), normal) : unit_across(away, normal);
    if (u.dot(away) < 0) u = -u;
    return u;
  };
  Eigen::Vector3d u = frame(n0), v = n0.cross(u);
  const std::optional<Eigen::Vector3d> under = bone_normal_under(bone, r, u, v, n0, p);
  if (!under) {
    out.problem = "no bone beyond the implant's edge there";
    return out;
  }
  const Eigen::Vector3d normal = *under;
  u = frame(normal);
  v = normal.cross(u);
  for (double at = 0.0; at <= p.length_mm + 1e-9; at += 0.25 * p.length_mm)
    for (const double across : {-0.5, 0.0, 0.5}) {
      const Eigen::Vector3d m = r + at * u + across * p.width_mm * v;
      const auto hit = bone.first_hit(m + 8.0 * normal, m - 8.0 * normal);
      if (!hit) continue;
      const double z = (hit->point - r).dot(normal);
      const double turn =
          std::acos(std::clamp(std::abs(bone.face_normal(hit->face).dot(normal)), 0.0, 1.0)) *
          180.0 / M_PI;
      if (at > 0.0) out.bone_turn_deg = std::max(out.bone_turn_deg, turn);
      out.bone_high = std::max(out.bone_high, z);
    }
  out.edge_height = 1e9;
  for (const double across : {-0.25, 0.0, 0.25})
    for (double at = 0.25; at <= 0.5 * p.length_mm; at += 0.25) {
      const Eigen::Vector3d m = r + at * u + across * p.width_mm * v;
      const auto hit = bone.first_hit(m + 8.0 * normal, m - 8.0 * normal);
      if (!hit || bone.face_normal(hit->face).dot(normal) < 0.7) continue;
      out.edge_height = std::min(out.edge_height, (hit->point - r).dot(normal));
      break;
    }
  if (out.edge_height > 1e8) {
    out.problem = "no outer table next to the implant's edge there";
    return out;
  }
  out.implant_high = -1e9;
  for (const double at : {0.0, -0.5 * kOverlapMm, -kOverlapMm})
    for (const double across : {-0.5, 0.0, 0.5}) {
      const Eigen::Vector3d m = r + at * u + across * p.width_mm * v;
      const auto hit = self.first_hit(m + 12.0 * normal, m - 12.0 * normal);
      if (hit) out.implant_high = std::max(out.implant_high, (hit->point - r).dot(normal));
    }
  out.implant_high = std::max(out.implant_high, out.bone_high);
  // A tab lies on both: the implant's outer surface next to its edge and the bone's beyond the
  // gap must be no further apart than its thickness.
  const Eigen::Vector3d m = r - 1.0 * u;
  if (const auto hit = self.first_hit(m + 12.0 * normal, m - 12.0 * normal)) {
    const double step = (hit->point - r).dot(normal) - out.edge_height;
    if (std::abs(step) > p.thickness_mm) {
      char buf[160];
      std::snprintf(buf, sizeof(buf),
                    "the implant's surface at its edge lies %.1f mm %s the bone's there (a tab "
                    "bridges at most its thickness, %.1f mm)",
                    std::abs(step), step > 0 ? "above" : "below", p.thickness_mm);
      out.problem = buf;
      return out;
    }
  }
  tab.rim = r;
  tab.outward = u;
  tab.normal = normal;
  tab.length_mm = p.length_mm;
  tab.width_mm = p.width_mm;
  tab.thickness_mm = p.thickness_mm;
  tab.bone_mm = 30.0;
  for (const double at : screw_positions(p)) {
    const Eigen::Vector3d m = r + at * u;
    const auto top = bone.first_hit(m + 8.0 * normal, m - 8.0 * normal);
    if (!top) {
      out.problem = "no bone under a screw";
      return out;
    }
    const auto under = bone.first_hit(top->point - 1e-3 * normal, top->point - 30.0 * normal);
    tab.bone_mm = std::min(tab.bone_mm, under ? under->distance : 30.0);
    tab.screws.push_back({top->point + (kUndersideMm + p.thickness_mm) * normal, normal, false});
  }
  if (p.midline) tab.midline_mm = midline_distance(*p.midline, tab, v);
  return out;
}

// Bone that turns more than this under a tab (a ridge, crushed fragments) does not carry one.
constexpr double kMaxBoneTurnDeg = 35.0;

bool allowed(const Candidate& c, const TabParams& p) {
  return c.problem.empty() && c.tab.bone_mm >= p.min_bone_mm &&
         c.bone_turn_deg <= kMaxBoneTurnDeg &&
         (!p.midline || c.tab.midline_mm >= p.midline_distance_mm);
}

// The even placement: `count` rim samples as evenly spaced along the rim as the allowed samples
// permit. Every offset of the ideal spacing in 0.5 mm steps is tried; each ideal place takes
// the nearest allowed sample within half the spacing not taken yet; the offset that places the
// most tabs, then with the least displacement, wins (the first such).
std::vector<size_t> place_evenly(const Rim& rim, const std::vector<uint8_t>& ok, int count) {
  const size_t n = rim.points.size();
  const double spacing = rim.length / count;
  std::vector<size_t> best;
  double best_shift = 1e300;
  for (double offset = 0.0; offset < spacing; offset += 0.5) {
    std::vector<size_t> chosen;
    double shift = 0.0;
    for (int k = 0; k < count; ++k) {
      const double want = offset + k * spacing;
      size_t pick = n;
      double d_pick = 0.5 * spacing;
      for (size_t i = 0; i < n; ++i) {
        if (!ok[i] || std::find(chosen.begin(), chosen.end(), i) != chosen.end()) continue;
        double d = std::abs(rim.arc[i] - want);
        d = std::min(d, rim.length - d);
        if (d < d_pick) d_pick = d, pick = i;
      }
      if (pick == n) continue;
      chosen.push_back(pick);
      shift = std::max(shift, d_pick);
    }
    if (chosen.size() > best.size() || (chosen.size() == best.size() && shift < best_shift)) {
      best = chosen;
      best_shift = shift;
    }
  }
  std::sort(best.begin(), best.end());
  return best;
}

// A tab's underside and top over its plane, on a square grid of `step` mm in (a, b): a along
// the tab from its rim point, b across.
struct TabMaps {
  double step = 0.2, a0 = 0.0, b0 = 0.0;
  int na = 0, nb = 0;
  std::vector<double> under, top;  // heights along the tab's normal, mm
  double low = 0.0, high = 0.0;    // their extremes

  std::pair<double, double> at(double a, double b) const {
    const double fa = std::clamp((a - a0) / step, 0.0, na - 1.0),
                 fb = std::clamp((b - b0) / step, 0.0, nb - 1.0);
    const int ia = std::min(na - 2, static_cast<int>(fa)),
              ib = std::min(nb - 2, static_cast<int>(fb));
    const double ta = fa - ia, tb = fb - ib;
    auto lerp = [&](const std::vector<double>& m) {
      const auto c = [&](int x, int y) { return m[static_cast<size_t>(y) * na + x]; };
      return (1 - ta) * (1 - tb) * c(ia, ib) + ta * (1 - tb) * c(ia + 1, ib) +
             (1 - ta) * tb * c(ia, ib + 1) + ta * tb * c(ia + 1, ib + 1);
    };
    return {lerp(under), lerp(top)};
  }
  std::pair<Eigen::Vector3d, Eigen::Vector3d> bounds(const Tab& t) const {
    const Eigen::Vector3d v = t.normal.cross(t.outward);
    Eigen::Vector3d lo = Eigen::Vector3d::Constant(1e300), hi = -lo;
    for (const double a : {a0, a0 + (na - 1) * step})
      for (const double b : {b0, b0 + (nb - 1) * step})
        for (const double z : {low - 0.5, high + 0.5}) {
          const Eigen::Vector3d x = t.rim + a * t.outward + b * v + z * t.normal;
          lo = lo.cwiseMin(x);
          hi = hi.cwiseMax(x);
        }
    return {lo, hi};
  }
};

TabMaps tab_maps(const Candidate& c, const SurfaceLocator& self, const SurfaceLocator& bone,
                 const TabParams& p) {
  const Tab& t = c.tab;
  const Eigen::Vector3d u = t.outward, n = t.normal, v = n.cross(u);
  TabMaps m;
  m.step = 0.2;
  const double margin = p.thickness_mm + 0.5;
  m.a0 = -kOverlapMm - margin;
  m.b0 = -0.5 * p.width_mm - margin;
  m.na = static_cast<int>(std::ceil((p.length_mm + margin - m.a0) / m.step)) + 1;
  m.nb = static_cast<int>(std::ceil((0.5 * p.width_mm + margin - m.b0) / m.step)) + 1;
  const size_t cells = static_cast<size_t>(m.na) * m.nb;
  // The outermost surface seen from above: the bone (plus the underside's gap) or the implant.
  const double reach = std::max(c.implant_high, c.bone_high) + 1.0;
  const double floor = c.edge_height - kPlugMm;
  std::vector<double> seen(cells);
  std::vector<uint8_t> over_implant(cells, 0);  // the underside lies on the implant there
  parallel_for(cells, [&](size_t begin, size_t end) {
    for (size_t q = begin; q < end; ++q) {
      const double a = m.a0 + static_cast<double>(q % m.na) * m.step,
                   b = m.b0 + static_cast<double>(q / m.na) * m.step;
      const Eigen::Vector3d x = t.rim + a * u + b * v;
      // Over the implant: on it (or on bone above it); beyond it, on the bone and no deeper
      // than the plug into the gap at the implant's edge.
      const double deepest = floor - (p.follow_implant ? p.thickness_mm + 1.0 : 1.0);
      const auto on_implant = self.first_hit(x + reach * n, x + deepest * n);
      double z = on_implant && p.follow_implant ? -1e300 : floor;
      if (const auto hit = bone.first_hit(x + reach * n, x + (floor - 1.0) * n))
        z = std::max(z, (hit->point - t.rim).dot(n) + kUndersideMm);
      if (on_implant) z = std::max(z, (on_implant->point - t.rim).dot(n));
      seen[q] = z;
      over_implant[q] = on_implant && z == (on_implant->point - t.rim).dot(n);
    }
  });
  // No deeper than kCrackDepthMm below the highest within kCrackRadiusMm: the gap at the
  // implant's edge (and a crack in the bone) narrower than twice that is bridged, not filled
  // with a fin. Where the implant is the outermost surface, the underside comes down onto its
  // rounded edge (over which the bridging would hold the tab with air under it); the top is
  // made on the bridged underside, so the tab's top does not dip where it does.
  const int r1 = static_cast<int>(std::round(kCrackRadiusMm / m.step));
  m.under.assign(cells, 0.0);
  std::vector<double> bridged(cells);  // the underside with every narrow gap bridged
  for (int y = 0; y < m.nb; ++y)
    for (int x = 0; x < m.na; ++x) {
      double highest = -1e300;
      for (int dy = -r1; dy <= r1; ++dy)
        for (int dx = -r1; dx <= r1; ++dx) {
          const int xx = x + dx, yy = y + dy;
          if (xx < 0 || yy < 0 || xx >= m.na || yy >= m.nb || dx * dx + dy * dy > r1 * r1) continue;
          highest = std::max(highest, seen[static_cast<size_t>(yy) * m.na + xx]);
        }
      const size_t q = static_cast<size_t>(y) * m.na + x;
      bridged[q] = std::max(seen[q], highest - kCrackDepthMm);
      // Down to the implant where it lies up to kFillFullMm below the bridged underside, not
      // at all where kFillNoneMm or more, part of the way in between: the underside stays
      // continuous where the implant's edge drops away under the tab's side.
      const double below = bridged[q] - seen[q];
      const double fill =
          p.on_implant_edge && over_implant[q]
              ? std::clamp((kFillNoneMm - below) / (kFillNoneMm - kFillFullMm), 0.0, 1.0)
              : 0.0;
      m.under[q] = bridged[q] - fill * below;
    }
  // The top: the upper envelope of the balls of the thickness on the bridged underside.
  const int rt = static_cast<int>(std::ceil(p.thickness_mm / m.step));
  m.top.assign(cells, 0.0);
  parallel_for(
      static_cast<size_t>(m.nb),
      [&](size_t begin, size_t end) {
        for (size_t y = begin; y < end; ++y)
          for (int x = 0; x < m.na; ++x) {
            double top = -1e300;
            for (int dy = -rt; dy <= rt; ++dy)
              for (int dx = -rt; dx <= rt; ++dx) {
                const int xx = x + dx, yy = static_cast<int>(y) + dy;
                if (xx < 0 || yy < 0 || xx >= m.na || yy >= m.nb) continue;
                const double r2 = p.thickness_mm * p.thickness_mm -
                                  m.step * m.step * static_cast<double>(dx * dx + dy * dy);
                if (r2 < 0) continue;
                top = std::max(top, bridged[static_cast<size_t>(yy) * m.na + xx] + std::sqrt(r2));
              }
            m.top[y * m.na + x] = top;
          }
      },
      1);
  m.low = *std::min_element(m.under.begin(), m.under.end());
  m.high = *std::max_element(m.top.begin(), m.top.end());
  return m;
}

}  // namespace

std::string tab_problem(const TabParams& p) {
  constexpr const char* kWhose = "the tabs'";
  if (std::string problem = range_problems(kWhose, p); !problem.empty()) return problem;
  // As many tabs placed by hand as the even placement may put.
  const auto max_tabs = static_cast<size_t>(spec_of<TabParams>("count").max);
  if (p.positions.size() > max_tabs)
    return "at most " + std::to_string(max_tabs) + " tabs may be placed";
  for (const auto& x : p.positions)
    if (!x.allFinite()) return "a tab's position is not a point";
  const ParamSpec countersink = spec_of<TabParams>("countersink_diameter_mm");
  if (p.countersink_diameter_mm != 0.0 && p.countersink_diameter_mm < p.screw_diameter_mm + 0.2)
    return countersink.problem(kWhose, p.countersink_diameter_mm, p.screw_diameter_mm + 0.2,
                               countersink.max);
  const double head = std::max(p.countersink_diameter_mm, p.screw_diameter_mm);
  const ParamSpec width = spec_of<TabParams>("width_mm");
  if (!std::isnan(p.width_mm) && head > p.width_mm - 1.0)
    return width.problem(kWhose, p.width_mm, head + 1.0, width.max);
  const ParamSpec thickness = spec_of<TabParams>("thickness_mm");
  if (!std::isnan(p.thickness_mm) && p.thickness_mm - countersink_depth(p) < 0.5)
    return thickness.problem(kWhose, p.thickness_mm, countersink_depth(p) + 0.5, thickness.max) +
           " (the countersink is " + std::to_string(countersink_depth(p)).substr(0, 4) +
           " mm deep)";
  // The innermost screw's head clear of the gap at the implant's edge (up to 3 mm).
  if (!std::isnan(p.width_mm)) {
    const double inner = screw_positions(p).back() - 0.5 * head;
    const ParamSpec length = spec_of<TabParams>("length_mm");
    if (inner < 3.5)
      return length.problem(kWhose, p.length_mm, p.length_mm + 3.5 - inner, length.max) +
             (p.screws == 2 ? " for two screws" : "");
  }
  if (p.midline && (!p.midline->normal.allFinite() || !std::isfinite(p.midline->offset) ||
                    std::abs(p.midline->normal.norm() - 1.0) > 1e-6))
    return "the midline plane for the tabs is not a plane";
  return {};
}

TabParams resolved(const TabParams& p, double material_min_thickness_mm) {
  TabParams out = p;
  const double wall = std::isnan(material_min_thickness_mm) ? 1.0 : material_min_thickness_mm;
  const double head = std::max(p.countersink_diameter_mm, p.screw_diameter_mm);
  if (std::isnan(out.width_mm)) out.width_mm = std::max(6.0, head + 2.0 * (wall + 0.5));
  if (std::isnan(out.thickness_mm))
    out.thickness_mm = std::max(1.5, wall + countersink_depth(p) + 0.4);
  return out;
}

double tab_gap(const SurfaceLocator& self, const SurfaceLocator& bone, const Tab& tab) {
  const Eigen::Vector3d u = tab.outward, n = tab.normal, v = n.cross(u);
  // Points every kStep mm inside the outline, shrunk by 0.75 mm (the round end), from 0.5 mm
  // beyond the implant's edge; `back` more rows nearer the edge only tell where the bone is.
  constexpr double kStep = 0.25;
  const int r = static_cast<int>(std::floor(kCrackRadiusMm / kStep + 1e-9)), back = r;
  const double half = 0.5 * tab.width_mm - 0.75, end = tab.length_mm - 0.5 * tab.width_mm;
  const double a0 = 0.5 - back * kStep;
  const int na = static_cast<int>(std::floor((tab.length_mm - 0.75 - a0) / kStep + 1e-9)) + 1,
            nb = static_cast<int>(std::floor(2.0 * half / kStep + 1e-9)) + 1;
  if (na <= back || nb < 1) return std::numeric_limits<double>::quiet_NaN();
  const size_t cells = static_cast<size_t>(na) * nb;
  // The gap where the bone's outer table faces the tab (not its cut face or the rounding into
  // it), off the screw holes; NaN elsewhere. `table`: the outer table lies under the point.
  std::vector<double> gap(cells, std::numeric_limits<double>::quiet_NaN());
  std::vector<uint8_t> table(cells, 0);
  parallel_for(cells, [&](size_t first, size_t last) {
    for (size_t q = first; q < last; ++q) {
      const int x = static_cast<int>(q % static_cast<size_t>(na));
      const double a = a0 + kStep * x, b = -half + kStep * static_cast<double>(q / na);
      const Eigen::Vector3d m = tab.rim + a * u + b * v;
      const auto top = bone.first_hit(m + 8.0 * n, m - 8.0 * n);
      if (!top || std::abs(bone.face_normal(top->face).dot(n)) < 0.9) continue;
      table[q] = 1;
      if (x < back || (a > end && std::hypot(a - end, b) > 0.5 * tab.width_mm - 0.75)) continue;
      bool by_screw = false;
      for (const Hole& s : tab.screws) {
        const Eigen::Vector3d d = s.center - m;
        by_screw = by_screw || (d - d.dot(n) * n).norm() < 0.5 * tab.width_mm - 0.5;
      }
      if (by_screw) continue;
      const auto under = self.first_hit(top->point - 0.5 * n, top->point + 8.0 * n);
      gap[q] = under ? under->distance - 0.5 : 7.5;
    }
  });
  // The underside bridges narrow gaps as it is made (kCrackRadiusMm, kCrackDepthMm): within
  // that reach beyond the bone's edge (the gap at the implant's edge and the bone's rounding
  // into it), where the tab spans the gap, a point does not count; elsewhere each point takes
  // the smallest gap within that reach (the tab rests on the bone on either side of a crack).
  double worst = -1e9;
  bool any = false;
  for (int y = 0; y < nb; ++y)
    for (int x = back; x < na; ++x) {
      const size_t q = static_cast<size_t>(y) * na + x;
      if (std::isnan(gap[q])) continue;
      bool beyond_edge = true;
      for (int s = 1; s <= back; ++s) beyond_edge = beyond_edge && table[q - s];
      if (!beyond_edge) continue;
      double nearest = gap[q];
      for (int dy = -r; dy <= r; ++dy)
        for (int dx = -r; dx <= r; ++dx) {
          const int xx = x + dx, yy = y + dy;
          if (xx < back || yy < 0 || xx >= na || yy >= nb ||
              kStep * kStep * (dx * dx + dy * dy) > kCrackRadiusMm * kCrackRadiusMm + 1e-9)
            continue;
          const double g = gap[static_cast<size_t>(yy) * na + xx];
          if (!std::isnan(g)) nearest = std::min(nearest, g);
        }
      worst = std::max(worst, nearest);
      any = true;
    }
  return any ? worst : std::numeric_limits<double>::quiet_NaN();
}

namespace {

// Why tabs placed this close overlap, or empty.
std::string overlap_problem(const std::vector<Candidate>& placed, const TabParams& p) {
  for (size_t i = 0; i < placed.size(); ++i)
    for (size_t j = i + 1; j < placed.size(); ++j)
      if ((placed[i].tab.rim - placed[j].tab.rim).norm() < p.width_mm + 1.0)
        return "tabs " + std::to_string(i + 1) + " and " + std::to_string(j + 1) +
               " overlap: move one along the rim";
  return {};
}

// The implant with the tabs `placed` meshed in `into`: empty, or why they cannot be.
std::string mesh_tabs(const SkullMesh& implant, const SurfaceLocator& self,
                      const SurfaceLocator& bone, const std::vector<Candidate>& placed,
                      const TabParams& p, SkullMesh& into) {
  const double sink = countersink_depth(p);
  // Each tab as two height maps over its plane (along its normal, from its rim point): its
  // underside, the outermost of the bone (kUndersideMm above it) and the implant seen from
  // above, bridging narrow gaps (the clearance at the implant's edge) and no deeper than kPlugMm
  // below the outer table at the edge; and its top, the envelope of the balls of its thickness
  // on the underside (so it is that thick across any slope).
  std::vector<TabMaps> maps;
  for (const Candidate& c : placed) maps.push_back(tab_maps(c, self, bone, p));

  // The grid: the implant and every tab.
  auto [lo, hi] = mesh_bounds(implant);
  for (size_t k = 0; k < placed.size(); ++k) {
    const auto [tlo, thi] = maps[k].bounds(placed[k].tab);
    lo = lo.cwiseMin(tlo);
    hi = hi.cwiseMax(thi);
  }
  const VoxelGrid g =
      VoxelGrid::covering_at_most(lo, hi, p.voxel_mm, std::max(1e5, p.max_voxels), 3);
  const double h = g.spacing;
  const std::vector<uint8_t> solid = voxelize_mesh(implant, g);
  std::vector<float> field = signed_distance_near_surface(self, solid, g);

  for (size_t k = 0; k < placed.size(); ++k) {
    const Tab& t = placed[k].tab;
    const TabMaps& m = maps[k];
    const Eigen::Vector3d u = t.outward, n = t.normal, v = n.cross(u);
    const auto [blo, bhi] = m.bounds(t);
    int i0[3], i1[3];
    for (int d = 0; d < 3; ++d) {
      i0[d] = std::max(0, static_cast<int>(std::floor((blo[d] - g.origin[d]) / h)) - 1);
      i1[d] = std::min(g.dims[d] - 1, static_cast<int>(std::ceil((bhi[d] - g.origin[d]) / h)) + 1);
    }
    const size_t nx = static_cast<size_t>(i1[0] - i0[0] + 1),
                 ny = static_cast<size_t>(i1[1] - i0[1] + 1),
                 nz = static_cast<size_t>(i1[2] - i0[2] + 1);
    const double end = p.length_mm - 0.5 * p.width_mm;
    parallel_for(nx * ny * nz, [&](size_t begin, size_t stop) {
      for (size_t s = begin; s < stop; ++s) {
        const int i = i0[0] + static_cast<int>(s % nx), j = i0[1] + static_cast<int>((s / nx) % ny),
                  kk = i0[2] + static_cast<int>(s / (nx * ny));
        const Eigen::Vector3d d = g.center(i, j, kk) - t.rim;
        const double a = d.dot(u), b = d.dot(v), z = d.dot(n);
        // Inside the outline: from kOverlapMm over the implant (a straight end, its corners
        // rounded) to the round far end.
        const double along = std::clamp(a, -kOverlapMm, end);
        const double outline =
            smooth_min(0.5 * p.width_mm - std::hypot(std::max(a - along, 0.0), b), a + kOverlapMm,
                       kEdgeRoundMm);
        if (outline < -2.0 * h) continue;
        const auto [under, top] = m.at(a, b);
        // Its top edges rounded: where the top slopes across the tab, a side wall along the
        // normal would meet it at a sharp angle.
        const double in_tab = std::min(z - under, smooth_min(top - z, outline, kEdgeRoundMm));
        float& f = field[g.index(i, j, kk)];
        f = std::max(f, static_cast<float>(in_tab));
      }
    });
  }
  // The screw holes: a cylinder through the tab and a 90° countersink at its top.
  for (const Candidate& c : placed)
    for (const Hole& s : c.tab.screws) {
      const double radius = 0.5 * p.screw_diameter_mm;
      const double below = p.thickness_mm + kUndersideMm + kPlugMm + 3.0;
      const double reach =
          std::max(0.5 * p.countersink_diameter_mm, radius) + 2.0 * h + below + 1.0;
      for_voxels_near(g, s.center, reach, [&](int i, int j, int k) {
        const Eigen::Vector3d q = g.center(i, j, k) - s.center;
        const double z = q.dot(s.axis);
        if (z > 1.0 + 2.0 * h || z < -below) return;
        const double off_axis = (q - z * s.axis).norm();
        const double open = radius + (sink > 0.0 ? std::max(0.0, z + sink) : 0.0);
        float& f = field[g.index(i, j, k)];
        f = std::min(f, static_cast<float>(off_axis - open));
      });
    }
  const ExtractBoneSurfaceResult mesh =
      surface_of_signed_distance(std::move(field), g, into, p.iso_gap);
  if (!mesh.usable()) return "joining the tabs to the implant: " + mesh.message;
  // The meshing keeps the largest piece: a tab that does not touch the implant would be gone
  // from the mesh while the result still counted it. Of six points inside each tab (a third,
  // half and two thirds along it, a third of its width to either side: off its screws and
  // their countersinks, which lie along its middle), one must lie inside the joined solid (an
  // odd number of crossings along the tab's normal). Also on replaying a plan saved before
  // follow_implant: such a plan exported the implant without the tab.
  const SurfaceLocator joined(into);
  auto inside_joined = [&](const Eigen::Vector3d& from, const Eigen::Vector3d& to) {
    return joined.hits_along(from, to).size() % 2 == 1;
  };
  for (size_t k = 0; k < placed.size(); ++k) {
    const Tab& t = placed[k].tab;
    const Eigen::Vector3d v = t.normal.cross(t.outward);
    bool joins = false;
    for (const double along : {1.0 / 3.0, 0.5, 2.0 / 3.0})
      for (const double across : {-1.0 / 3.0, 1.0 / 3.0}) {
        const double a = along * p.length_mm, b = across * p.width_mm;
        const auto [under, top] = maps[k].at(a, b);
        const Eigen::Vector3d mid = t.rim + a * t.outward + b * v + 0.5 * (under + top) * t.normal;
        joins = joins ||
                inside_joined(mid, mid + (maps[k].high - 0.5 * (under + top) + 20.0) * t.normal);
      }
    if (!joins)
      return "tab " + std::to_string(k + 1) +
             " does not join the implant (it would stand apart from it): move it along the rim";
  }
  return {};
}

// add_fixation_tabs, the implant with its tabs meshed in `into` (the result's own mesh, or the
// caller's).
void tabs_into(const SkullMesh& implant, const SurfaceLocator& bone, const Eigen::Vector3d& inside,
               const TabParams& p, TabResult& r, SkullMesh& into) {
  assert(&into != &implant && "the tabs are meshed into another mesh than the implant");
  const auto t0 = std::chrono::steady_clock::now();
  auto fail = [&](const std::string& message) {
    r.status = TabResult::Status::Failed;
    r.message = message;
    into = implant;
    r.tabs.clear();
    r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  };
  if (const std::string problem = tab_problem(p); !problem.empty()) return fail(problem);
  if (std::isnan(p.width_mm) || std::isnan(p.thickness_mm))
    return fail("the tabs' width and thickness are not set");
  const SurfaceLocator self(implant);
  const Rim rim = trace_rim(self, implant, bone, inside);
  r.rim_length_mm = rim.length;
  if (rim.points.size() < 12) return fail("the implant has no edge to put tabs on");

  // Where the tabs go: the user's (each at the nearest rim sample), or evenly along the rim.
  std::vector<Candidate> placed;
  if (!p.positions.empty()) {
    for (size_t k = 0; k < p.positions.size(); ++k) {
      size_t at = 0;
      for (size_t i = 1; i < rim.points.size(); ++i)
        if ((rim.points[i] - p.positions[k]).squaredNorm() <
            (rim.points[at] - p.positions[k]).squaredNorm())
          at = i;
      Candidate c = make_tab(rim, at, self, bone, inside, p);
      if (!c.problem.empty())
        return fail("tab " + std::to_string(k + 1) + ": " + c.problem +
                    " (move it along the rim onto bone)");
      c.tab.added = true;
      placed.push_back(std::move(c));
    }
    if (const std::string problem = overlap_problem(placed, p); !problem.empty())
      return fail(problem);
    if (const std::string problem = mesh_tabs(implant, self, bone, placed, p, into);
        !problem.empty())
      return fail(problem);
  } else {
    const int count =
        p.count > 0 ? p.count
                    : std::clamp(static_cast<int>(std::lround(rim.length / kRimPerTabMm)), 3, 8);
    std::vector<Candidate> all(rim.points.size());
    std::vector<uint8_t> ok(rim.points.size());
    parallel_for(
        rim.points.size(),
        [&](size_t begin, size_t end) {
          for (size_t i = begin; i < end; ++i) {
            all[i] = make_tab(rim, i, self, bone, inside, p);
            ok[i] = allowed(all[i], p);
          }
        },
        8);
    // Placed, meshed, and each tab's rest on the bone measured as the quality report measures
    // it (tab_gap on the joined mesh): a tab standing off the bone by more than the report
    // allows (over uneven fragments, a step down beyond the edge) is placed again away from
    // there, its rim samples within a tab's width no longer used.
    int moved = 0;
    for (int round = 0;; ++round) {
      placed.clear();
      for (size_t i : place_evenly(rim, ok, count)) placed.push_back(all[i]);
      if (placed.empty())
        return fail("no stretch of the rim has bone at least " + std::to_string(p.min_bone_mm) +
                    " mm thick beyond it" + (p.midline ? " away from the midline" : std::string()) +
                    (moved > 0 ? " on which a tab rests" : ""));
      if (const std::string problem = overlap_problem(placed, p); !problem.empty())
        return fail(problem);
      if (const std::string problem = mesh_tabs(implant, self, bone, placed, p, into);
          !problem.empty())
        return fail(problem);
      if (!p.keep_on_bone || round == kPlacementRounds) break;
      const SurfaceLocator joined(into);
      bool again = false;
      for (const Candidate& c : placed) {
        if (!(tab_gap(joined, bone, c.tab) > kRestsWithinMm)) continue;
        again = true;
        ++moved;
        for (size_t i = 0; i < rim.points.size(); ++i)
          if ((rim.points[i] - c.tab.rim).norm() < p.width_mm) ok[i] = 0;
      }
      if (!again) break;
    }
    r.message.clear();
    if (static_cast<int>(placed.size()) < count)
      r.message = "only " + std::to_string(placed.size()) + " of " + std::to_string(count) +
                  " tabs find bone thick enough" + (p.midline ? " away from the midline" : "") +
                  "; ";
    if (moved > 0)
      r.message += std::to_string(moved) + (moved == 1 ? " tab" : " tabs") +
                   " moved along the rim from where " + (moved == 1 ? "it" : "they") +
                   " would stand off the bone; ";
  }
  for (Candidate& c : placed) r.tabs.push_back(std::move(c.tab));
  r.status = TabResult::Status::Added;
  char buf[160];
  const size_t screws = r.tabs.size() * static_cast<size_t>(p.screws);
  std::snprintf(buf, sizeof(buf), "%zu %s with %zu screw %s of %.1f mm", r.tabs.size(),
                r.tabs.size() == 1 ? "tab" : "tabs", screws, screws == 1 ? "hole" : "holes",
                p.screw_diameter_mm);
  r.message += buf;
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace

TabResult add_fixation_tabs(const SkullMesh& implant, const SurfaceLocator& bone,
                            const Eigen::Vector3d& inside, const TabParams& params) {
  TabResult r;
  tabs_into(implant, bone, inside, params, r, r.mesh);
  return r;
}

TabResult add_fixation_tabs(const SkullMesh& implant, const SurfaceLocator& bone,
                            const Eigen::Vector3d& inside, const TabParams& params,
                            SkullMesh& into) {
  TabResult r;
  tabs_into(implant, bone, inside, params, r, into);
  return r;
}

}  // namespace cranioplan
