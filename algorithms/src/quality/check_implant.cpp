#include "cranioplan/algorithms/quality/check_implant.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <future>
#include <memory>
#include <utility>

#include "cranioplan/algorithms/geometry/distance_transform.h"
#include "cranioplan/algorithms/geometry/self_intersections.h"
#include "cranioplan/algorithms/geometry/surface_locator.h"
#include "cranioplan/algorithms/geometry/voxelize_mesh.h"
#include "cranioplan/algorithms/implant/build_implant.h"
#include "cranioplan/algorithms/io/mesh_report.h"
#include "cranioplan/algorithms/quality/thickness_map.h"
#include "cranioplan/model/parallel.h"
#include "cranioplan/model/plane.h"

namespace cranioplan {
namespace {
std::string fmt(const char* f, double a, double b) {
  char buf[200];
  std::snprintf(buf, sizeof(buf), f, a, b);
  return buf;
}
std::string fmt1(const char* f, double a) {
  char buf[64];
  std::snprintf(buf, sizeof(buf), f, a);
  return buf;
}

// A measure over its limit, to a tenth of a millimetre, or finer where a tenth would read as
// the limit itself ("for 2.0 mm; may be 2.0 mm").
std::string over_limit(double value, double limit) {
  for (const char* f : {"%.1f", "%.2f"})
    if (fmt1(f, value) != fmt1(f, limit)) return fmt1(f, value);
  return fmt1("%.3f", value);
}
// How near the bone thin material counts as the tapered edge of an implant resting on it, mm:
// its own thinness, a voxel and a half, and the widest clearance asked.
double on_bone_mm(const QualityParams& params, double h) {
  double clearance = params.edge_clearance_mm;
  for (const ClearanceZone& z : params.clearance_zones)
    clearance = std::max(clearance, z.clearance_mm);
  return params.min_thickness_mm + 1.5 * h + std::max(0.0, clearance);
}

// Material thinner than the minimum: the solid minus its opening by a ball of that diameter
// (the union of the balls that fit inside). Where it lies within its own thinness of the bone
// (and the clearance asked) it is the tapered edge of an implant resting on the bone; how far
// it reaches from the thick part is the width of that taper.
void measure_thin_material(const std::vector<uint8_t>& solid, const std::vector<float>& depth,
                           const VoxelGrid& grid, const std::vector<float>& bone_distance,
                           const QualityParams& params, QualityReport& q) {
  const double r = 0.5 * std::max(0.0, params.min_thickness_mm), h = grid.spacing;
  const std::vector<uint8_t> centres = ball_centres(depth, grid, r);
  if (std::find(centres.begin(), centres.end(), 1) == centres.end()) {
    q.taper_reach_mm = q.corner_reach_mm = -1.0;
    return;
  }
  // Only the thin voxels' distances to the core are asked: within the widest taper and corner
  // allowed (and a millimetre) first, in full when one lies further (a refused plan's figure).
  const double window = r + h + std::max(params.max_taper_mm, params.max_corner_mm) + 1.0;
  std::vector<float> to_core = distance_to_mask(centres, grid, window);
  for (size_t c = 0; c < solid.size(); ++c)
    if (solid[c] && std::isinf(to_core[c])) {
      to_core = distance_to_mask(centres, grid);
      break;
    }
  // An edge held a clearance off the bone tapers that much further from it.
  const double on_bone = on_bone_mm(params, h);
  size_t thin = 0, off_bone = 0;
  for (size_t c = 0; c < solid.size(); ++c) {
    if (!solid[c] || to_core[c] <= r + h) continue;  // within a ball that fits (one voxel slack)
    ++thin;
    const double reach = static_cast<double>(to_core[c]) - r;
    if (!bone_distance.empty() && bone_distance[c] <= on_bone) {
      q.taper_reach_mm = std::max(q.taper_reach_mm, reach);
    } else {
      ++off_bone;
      q.corner_reach_mm = std::max(q.corner_reach_mm, reach);
    }
  }
  q.thin_volume_mm3 = static_cast<double>(thin) * grid.voxel_volume();
  q.thin_off_bone_mm3 = static_cast<double>(off_bone) * grid.voxel_volume();
}

}  // namespace

std::optional<Eigen::Vector3d> rim_gap_to_mark(const QualityReport& report) {
  if (!report.clearance_asked && report.rim_gap_mm > kRimGapTargetMm) return report.rim_gap_at;
  if (report.clearance_asked && report.clearance_high_mm > kRimGapTargetMm)
    return report.clearance_high_at;
  return std::nullopt;
}

namespace {

// Thickness across the plate from at most 60,000 faces spread evenly over the implant (one ray
// each along the inward normal, for faces within 45° of `axis`): a mesh trimmed on a fine grid
// has hundreds of thousands of faces, and a thin region spans many. The other faces' vertices
// are the side wall's, returned in `wall_vertices`.
std::vector<double> thickness_samples(const SkullMesh& implant, const SurfaceLocator& self,
                                      const Eigen::Vector3d& axis, const std::vector<float>& depth,
                                      const VoxelGrid& grid, std::vector<int>& wall_vertices) {
  const size_t stride = std::max<size_t>(1, (implant.n_faces() + 59999) / 60000);
  std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>> rays;  // from, inward normal
  for (auto fh : implant.faces()) {
    const bool measure = static_cast<size_t>(fh.idx()) % stride == 0;
    const FaceCorners f = face_corners(implant, fh);
    Eigen::Vector3d n = f.cross();
    if (n.norm() == 0) continue;
    n.normalize();
    if (across_plate(n, axis)) {
      if (!measure) continue;
      // Where the plate curves, a normal can leave it at a grazing angle and run along it, far
      // further than the plate is thick (docs/IMPLANT.md, the quality report's thickness): the
      // thickness there is at most the diameter of the deepest ball the ray passes.
      rays.emplace_back((f.p[0] + f.p[1] + f.p[2]) / 3.0, n);
    } else {
      wall_vertices.insert(wall_vertices.end(), f.ids.begin(), f.ids.end());
    }
  }
  // The rays on all threads, each thickness in its face's place.
  std::vector<double> through(rays.size());
  parallel_for(
      rays.size(),
      [&](size_t first, size_t last) {
        for (size_t i = first; i < last; ++i)
          through[i] = thickness_through(self, rays[i].first, rays[i].second, depth, grid);
      },
      256);
  std::vector<double> thickness;
  for (double t : through)
    if (t > 0.0) thickness.push_back(t);
  return thickness;
}

// Whether `p` belongs to tab `t` or to the edge it bridges: within 1 mm of its outline, from
// 6 mm below its rim point to 12 mm above (a tab climbs onto bone higher than the implant's edge).
bool under_tab(const Tab& t, const Eigen::Vector3d& p) {
  const Eigen::Vector3d d = p - t.rim, v = t.normal.cross(t.outward);
  const double a = d.dot(t.outward);
  return a <= t.length_mm + 1.0 && std::abs(d.dot(v)) <= 0.5 * t.width_mm + 1.0 &&
         d.dot(t.normal) >= -6.0 && d.dot(t.normal) <= 12.0 && a >= -6.0;
}

// The tabs: each one's gap to the bone, its screws through, the bone under them, the midline.
void measure_tabs(const SurfaceLocator& self, const SurfaceLocator* bone,
                  const QualityParams& params, QualityReport& q) {
  q.tabs = static_cast<int>(params.tabs.size());
  if (params.tabs.empty()) return;
  for (const Tab& t : params.tabs) {
    for (const Hole& s : t.screws) q.screws_blocked += !hole_goes_through(self, s);
    q.tab_bone_mm = q.tab_bone_mm < 0 ? t.bone_mm : std::min(q.tab_bone_mm, t.bone_mm);
    if (!std::isnan(t.midline_mm))
      q.tab_midline_mm =
          q.tab_midline_mm < 0 ? t.midline_mm : std::min(q.tab_midline_mm, t.midline_mm);
  }
  if (!bone) return;
  for (size_t k = 0; k < params.tabs.size(); ++k) {
    const double gap = tab_gap(self, *bone, params.tabs[k]);
    if (std::isnan(gap)) continue;
    if (k == 0 || std::abs(gap) > std::abs(q.tab_gap_mm)) q.tab_gap_mm = gap;
    if (gap > params.max_tab_gap_mm)
      q.reasons.push_back(fmt("tab %.0f stands up to %.2f mm off the bone", k + 1.0, gap) +
                          fmt1(" (limit %.2f mm)", params.max_tab_gap_mm));
    if (gap < -params.max_tab_gap_mm)
      q.reasons.push_back(fmt("tab %.0f enters the bone by %.2f mm", k + 1.0, -gap) +
                          fmt1(" (limit %.2f mm)", params.max_tab_gap_mm));
  }
  for (size_t k = 0; k < params.tabs.size(); ++k) {
    const Tab& t = params.tabs[k];
    if (t.bone_mm < params.tab_min_bone_mm)
      q.reasons.push_back(fmt("tab %.0f's screws go into bone %.1f mm thick", k + 1.0, t.bone_mm) +
                          fmt1(" (at least %.1f mm asked)", params.tab_min_bone_mm));
    if (!std::isnan(t.midline_mm) && t.midline_mm < params.tab_midline_mm)
      q.reasons.push_back(
          fmt("tab %.0f lies %.1f mm from the midsagittal plane", k + 1.0, t.midline_mm) +
          fmt1(" (at least %.1f mm asked: the sagittal sinus)", params.tab_midline_mm));
  }
}

// Against the skull: the gap along the rim (over every 5° arc around the implant's `axis`
// through `c`, the side-wall vertex nearest the bone; the rim gap is the worst arc) and the
// overlap on the implant's grid. The distance to the bone on that grid.
std::vector<float> measure_against_bone(const SkullMesh& implant, const SkullMesh& skull,
                                        const SurfaceLocator& bone, const Eigen::Vector3d& c,
                                        const Eigen::Vector3d& axis, std::vector<int> wall_vertices,
                                        const std::vector<uint8_t>& solid, const VoxelGrid& grid,
                                        const QualityParams& params, QualityReport& q) {
  const RimSamples s =
      rim_samples(implant, bone, c, axis, std::move(wall_vertices), params.scan_ends);
  size_t gap_at = 0;
  q.rim_gap_mm = worst_arc_gap(s.angle, s.distance, kRimArcRad, &gap_at);
  if (!s.vertices.empty()) {
    q.rim_gap_at = to_eigen(implant.point(SkullMesh::VertexHandle(s.vertices[gap_at])));
    q.rim_gap_bone = s.nearest[gap_at];
  }
  if (params.edge_clearance_mm > 0.0 || !params.clearance_zones.empty()) {
    // The excess of each wall vertex's gap over the clearance asked at the bone it faces: the
    // worst arc's (its nearest vertex to the bone) and the smallest of all. The edge a tab
    // bridges (with 1 mm to spare on each side) is as asked: the tab holds it.
    std::vector<bool> bridged(s.vertices.size());
    for (size_t i = 0; i < bridged.size(); ++i) {
      const Eigen::Vector3d p = to_eigen(implant.point(SkullMesh::VertexHandle(s.vertices[i])));
      bridged[i] = std::any_of(params.tabs.begin(), params.tabs.end(),
                               [&](const Tab& t) { return under_tab(t, p); });
    }
    const std::vector<double> excess =
        clearance_excess(s, params.edge_clearance_mm, params.clearance_zones, bridged);
    q.clearance_asked = true;
    size_t high_at = 0;
    q.clearance_high_mm = worst_arc_gap(s.angle, excess, kRimArcRad, &high_at);
    if (!s.vertices.empty())
      q.clearance_high_at = to_eigen(implant.point(SkullMesh::VertexHandle(s.vertices[high_at])));
    q.clearance_low_mm = excess.empty() ? 0.0 : *std::min_element(excess.begin(), excess.end());
  }
  const std::vector<uint8_t> b = voxelize_mesh(skull, grid);
  long long both = 0;
  for (size_t i = 0; i < solid.size(); ++i) both += solid[i] && b[i];
  q.penetration_mm3 = static_cast<double>(both) * grid.voxel_volume();
  // Only whether thin material lies within on_bone_mm of the bone is asked of it.
  return distance_to_mask(b, grid, on_bone_mm(params, grid.spacing));
}

// Why the implant is not printable, from what was measured.
void add_reasons(const MeshReport& rep, const QualityParams& params, bool with_bone,
                 QualityReport& q) {
  if (!q.watertight)
    q.reasons.push_back("not watertight (" + std::to_string(rep.boundary_edges) +
                        " boundary edges)");
  if (!q.manifold)
    q.reasons.push_back(std::to_string(rep.nonmanifold_edges) + " non-manifold edges");
  if (!q.outward) q.reasons.push_back("faces point inwards (negative volume)");
  if (q.self_intersections > 0)
    q.reasons.push_back(std::to_string(q.self_intersections) +
                        " pairs of triangles cross each other");
  if (q.taper_reach_mm < 0)
    q.reasons.push_back(fmt("nowhere is the implant %.2f mm thick (thickest %.2f mm)",
                            params.min_thickness_mm, q.thickness_max_mm));
  if (q.corner_reach_mm > params.max_corner_mm)
    q.reasons.push_back(fmt1(!with_bone ? "it is thinner than %.2f mm for "
                                        : "away from the bone it is thinner than %.2f mm for ",
                             params.min_thickness_mm) +
                        over_limit(q.corner_reach_mm, params.max_corner_mm) + " mm" + " (" +
                        fmt1("%.1f", q.thin_off_bone_mm3) + " mm³; a sharp corner may be " +
                        fmt1("%.1f", params.max_corner_mm) + " mm" +
                        (!with_bone
                             ? "; without the skull a tapered edge on the bone cannot be told"
                               " from a corner: check with the skull)"
                             : ")"));
  if (q.taper_reach_mm > params.max_taper_mm)
    q.reasons.push_back(fmt1("its edge stays thinner than %.2f mm for ", params.min_thickness_mm) +
                        over_limit(q.taper_reach_mm, params.max_taper_mm) + " mm" +
                        " (a tapered edge on the bone may be " + fmt1("%.1f", params.max_taper_mm) +
                        " mm wide)");
  if (!q.clearance_asked && q.rim_gap_mm > params.max_rim_gap_mm)
    q.reasons.push_back(fmt("gap of %.2f mm between the rim and the bone (limit %.2f mm)",
                            q.rim_gap_mm, params.max_rim_gap_mm) +
                        (q.rim_gap_at ? at_point_text(*q.rim_gap_at) : std::string()));
  if (q.clearance_asked && q.clearance_high_mm > params.max_rim_gap_mm)
    q.reasons.push_back(
        fmt("a gap %.2f mm wider than the clearance asked between the rim and "
            "the bone (limit %.2f mm)",
            q.clearance_high_mm, params.max_rim_gap_mm) +
        (q.clearance_high_at ? at_point_text(*q.clearance_high_at) : std::string()));
  if (q.clearance_asked && q.clearance_low_mm < -params.clearance_tolerance_mm)
    q.reasons.push_back(
        fmt("the edge comes %.2f mm nearer the bone than the clearance asked "
            "(tolerance %.2f mm): it would not go in",
            -q.clearance_low_mm, params.clearance_tolerance_mm));
  if (q.holes_blocked > 0)
    q.reasons.push_back(std::to_string(q.holes_blocked) + " of " + std::to_string(q.holes) +
                        " holes do not go through");
  if (q.screws_blocked > 0)
    q.reasons.push_back(std::to_string(q.screws_blocked) +
                        " of the tabs' screw holes do not go through");
  if (q.penetration_mm3 > params.max_penetration_mm3)
    q.reasons.push_back(fmt("%.1f mm³ overlap the skull (limit %.1f mm³)", q.penetration_mm3,
                            params.max_penetration_mm3));
}

}  // namespace

QualityParams quality_params_for(const std::optional<Material>& material,
                                 const std::vector<ClearanceZone>& zones) {
  QualityParams q;
  q.clearance_zones = zones;
  if (!material) return q;
  q.min_thickness_mm = material->min_thickness_mm;
  q.edge_clearance_mm = material->edge_clearance_mm;
  q.density_g_cm3 = material->density_g_cm3;
  q.material_name = material->name;
  return q;
}

QualityParams quality_params_for(const ImplantParams& params, const ImplantResult& result) {
  QualityParams q = quality_params_for(params.material, params.clearance_zones);
  q.holes = result.holes;
  q.tabs = result.tabs;
  q.scan_ends = params.scan_ends;
  if (!result.tabs.empty()) {
    q.tab_min_bone_mm = params.tabs.min_bone_mm;
    q.tab_midline_mm = params.tabs.midline ? params.tabs.midline_distance_mm : 0.0;
  }
  return q;
}

QualityReport check_implant(const SkullMesh& implant, const SkullMesh* skull,
                            const QualityParams& params) {
  return check_implant(implant, skull, nullptr, params);
}

QualityReport check_implant(const SkullMesh& implant, const SkullMesh* skull,
                            const SurfaceLocator* skull_locator, const QualityParams& params) {
  QualityReport q;
  q.ends_at_scan_end = !params.scan_ends.empty();
  // The mesh's own checks (its report and its self-intersections, partly on one thread) run
  // beside the checks on the grid; neither uses the other's results.
  std::future<std::pair<MeshReport, long long>> own_checks = std::async(beside(), [&implant] {
    return std::make_pair(report_mesh(implant), count_self_intersections(implant));
  });
  auto take_own_checks = [&] {
    const auto [rep, self_intersections] = own_checks.get();
    q.watertight = rep.watertight;
    q.manifold = rep.nonmanifold_edges == 0;
    q.volume_mm3 = rep.volume_mm3;
    q.area_mm2 = rep.area_mm2;
    q.outward = rep.volume_mm3 > 0;
    q.pieces = rep.pieces;
    q.self_intersections = self_intersections;
    if (params.density_g_cm3 > 0.0) q.mass_g = rep.volume_mm3 * 1e-3 * params.density_g_cm3;
    return rep;
  };
  q.material_name = params.material_name;
  if (implant.n_faces() == 0) {
    take_own_checks();
    q.reasons.push_back("the implant has no triangles");
    return q;
  }

  // Principal axes of the implant's vertices: the thinnest one is across the plate.
  const Eigen::Vector3d c = vertex_centroid(implant);
  const Eigen::Vector3d axis = plate_axis(implant, c);

  // The implant as a solid on a grid: its depth bounds the thickness, and it gives the thin
  // material and, with a skull, the overlap.
  const auto [lo, hi] = mesh_bounds(implant);
  const VoxelGrid grid =
      VoxelGrid::covering_at_most(lo, hi, std::clamp(params.overlap_voxel_mm, 0.05, 2.0),
                                  std::max(1e5, params.overlap_max_voxels));
  const std::vector<uint8_t> solid = voxelize_mesh(implant, grid);
  const std::vector<float> depth = depth_in_mask(solid, grid);

  const SurfaceLocator self(implant);
  q.holes = static_cast<int>(params.holes.size());
  for (const Hole& h : params.holes) q.holes_blocked += !hole_goes_through(self, h);
  std::vector<int> wall_vertices;
  std::vector<double> thickness =
      thickness_samples(implant, self, axis, depth, grid, wall_vertices);
  if (!thickness.empty()) {
    std::sort(thickness.begin(), thickness.end());
    q.thickness_min_mm = thickness.front();
    q.thickness_median_mm = thickness[thickness.size() / 2];
    q.thickness_max_mm = thickness.back();
  }
  std::vector<float> bone_distance;  // empty without a skull
  std::unique_ptr<SurfaceLocator> own;
  const SurfaceLocator* bone = nullptr;
  if (skull && skull->n_faces() > 0) {
    if (!skull_locator) own = std::make_unique<SurfaceLocator>(*skull);
    bone = skull_locator ? skull_locator : own.get();
    bone_distance = measure_against_bone(implant, *skull, *bone, c, axis, std::move(wall_vertices),
                                         solid, grid, params, q);
  }
  measure_thin_material(solid, depth, grid, bone_distance, params, q);
  const MeshReport rep = take_own_checks();
  add_reasons(rep, params, !bone_distance.empty(), q);
  measure_tabs(self, bone, params, q);
  q.printable = q.reasons.empty();
  return q;
}

}  // namespace cranioplan
