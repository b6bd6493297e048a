#include "cranioplan/algorithms/implant/build_implant.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include "cranioplan/algorithms/geometry/surface_locator.h"
#include "cranioplan/algorithms/implant/snap_markers.h"
#include "cranioplan/algorithms/io/mesh_report.h"
#include "cranioplan/algorithms/planning/detect_defect.h"
#include "cranioplan/algorithms/quality/check_implant.h"
#include "cranioplan/algorithms/quality/compare_implants.h"
#include "cranioplan/algorithms/quality/inject_defect.h"
#include "support/synthetic.h"

namespace cranioplan {
namespace {

// A thick synthetic skull with a round defect, its true implant and the markers around it.
struct DefectCase {
  SkullMesh defective, truth;
  std::vector<Marker> markers;
};

const DefectCase& right_parietal_case() {
  static const DefectCase c = [] {
    DefectCase d;
    const SkullMesh skull = test::make_thick_head();
    const Eigen::Vector3d dir = Eigen::Vector3d(0.7, 0.1, 0.7).normalized();
    const Eigen::Vector3d center = test::head_surface_point(dir) * 0.965;
    InjectDefectParams p;
    p.center = center;
    p.size_mm = 50;
    p.voxel_mm = 0.5;
    const InjectDefectResult r = inject_defect(skull, p);
    d.defective = r.defective;
    d.truth = r.implant;
    d.markers = test::round_defect_markers(center, 25.0);
    const SurfaceLocator bone(d.defective);
    d.markers = snap_markers(d.markers, bone, nullptr, SnapMarkersParams{}).markers;
    return d;
  }();
  return c;
}

// The words the reports and --json give each status.
TEST(BuildImplant, EachStatusHasItsWord) {
  EXPECT_STREQ(status_name(ImplantResult::Status::Built), "built");
  EXPECT_STREQ(status_name(ImplantResult::Status::TooFewMarkers), "too_few_markers");
  EXPECT_STREQ(status_name(ImplantResult::Status::Failed), "failed");
}

TEST(BuildImplant, ShellThroughMarkersIsWatertightAndPassesThroughEdgeMarkers) {
  const DefectCase& c = right_parietal_case();
  const ImplantResult r = build_implant(c.markers, &c.defective);
  ASSERT_TRUE(r.usable()) << r.message;
  EXPECT_TRUE(r.watertight);
  EXPECT_LT(r.rim_marker_error_mm, 0.05);
  const MeshReport rep = report_mesh(r.mesh);
  EXPECT_EQ(rep.pieces, 1);
  EXPECT_GT(rep.volume_mm3, 0);
  // Every edge marker is a vertex of the implant (within 0.05 mm).
  const SurfaceLocator implant(r.mesh);
  for (const auto& m : c.markers)
    if (is_edge(m.type)) {
      EXPECT_LT(implant.closest(m.position).distance, 0.05) << m.id;
    }
}

TEST(BuildImplant, ShellMatchesTheRemovedBone) {
  const DefectCase& c = right_parietal_case();
  const ImplantResult r = build_implant(c.markers, &c.defective);
  ASSERT_TRUE(r.usable()) << r.message;
  const CompareResult cmp = compare_implants(r.mesh, c.truth, &c.defective);
  EXPECT_GT(cmp.dice, 0.85) << "hd95 " << cmp.hd95_mm;
  EXPECT_LT(cmp.hd95_mm, 1.5);
  const QualityReport q = check_implant(r.mesh, &c.defective);
  EXPECT_TRUE(q.watertight);
  EXPECT_EQ(q.self_intersections, 0);
  EXPECT_LT(q.rim_gap_mm, 0.5);
  EXPECT_LT(q.penetration_mm3, 50.0);
}

TEST(BuildImplant, WithoutInnerMarkersTheShellIsOffsetByTheMeasuredBoneThickness) {
  const DefectCase& c = right_parietal_case();
  std::vector<Marker> outer_only;
  for (const auto& m : c.markers)
    if (is_outer(m.type)) outer_only.push_back(m);
  const ImplantResult r = build_implant(outer_only, &c.defective);
  ASSERT_TRUE(r.usable()) << r.message;
  EXPECT_TRUE(r.watertight);
  // The head wall is 7 % of a radius of ~75 mm: about 5 mm.
  EXPECT_GT(r.thickness_used_mm, 3.5);
  EXPECT_LT(r.thickness_used_mm, 7.0);
  EXPECT_GT(compare_implants(r.mesh, c.truth).dice, 0.75);
}

TEST(BuildImplant, Delaunay3dOverTheMarkers) {
  const DefectCase& c = right_parietal_case();
  ImplantParams p;
  p.method = ImplantMethod::Delaunay3D;
  const ImplantResult r = build_implant(c.markers, &c.defective, p);
  ASSERT_TRUE(r.usable()) << r.message;
  EXPECT_TRUE(r.watertight);  // alpha 0: the convex hull
  EXPECT_GT(report_mesh(r.mesh).volume_mm3, 0);
}

TEST(BuildImplant, TooFewMarkersGiveAStatus) {
  const std::vector<Marker> two = {{1, MarkerType::OuterEdge, {0, 0, 0}, MarkerSurface::Original},
                                   {2, MarkerType::OuterEdge, {1, 0, 0}, MarkerSurface::Original}};
  const ImplantResult r = build_implant(two, nullptr);
  EXPECT_EQ(r.status, ImplantResult::Status::TooFewMarkers);
  ImplantParams p;
  p.method = ImplantMethod::Delaunay3D;
  EXPECT_EQ(build_implant(two, nullptr, p).status, ImplantResult::Status::TooFewMarkers);
}

}  // namespace
}  // namespace cranioplan

namespace cranioplan {
namespace {

// A marker dragged through the opening onto the far wall of the skull must give a clear
// failure, not a runaway computation.
TEST(BuildImplant, AMarkerOnTheFarSideIsRefusedNotStretched) {
  const SkullMesh head = test::make_symmetric_head(4);
  const Eigen::Vector3d c = test::head_surface_point(Eigen::Vector3d(0.7, 0.1, 0.7).normalized());
  std::vector<Marker> markers = test::round_defect_markers(c * 0.965, 20.0);
  ASSERT_GT(markers.size(), 3u);
  markers.front().position = -markers.front().position;  // through the skull to the far side
  ImplantParams p;
  p.radial_center = Eigen::Vector3d::Zero();
  const ImplantResult r = build_implant(markers, &head, p);
  EXPECT_EQ(r.status, ImplantResult::Status::Failed);
  EXPECT_NE(r.message.find("far side"), std::string::npos) << r.message;
}

// The right parietal case fitted to the bone, with `material` and `zones`.
ImplantResult finished(const std::optional<Material>& material,
                       const std::vector<ClearanceZone>& zones = {}) {
  const DefectCase& c = right_parietal_case();
  ImplantParams p;
  p.fit_to_bone_mm = 4.0;
  p.material = material;
  p.clearance_zones = zones;
  return build_implant(c.markers, &c.defective, p);
}

Material peek_with(double clearance, double under_contour) {
  Material m = *material_preset("peek");
  m.edge_clearance_mm = clearance;
  m.under_contour_mm = under_contour;
  return m;
}

// Where the scan ended across the opening (ImplantParams::scan_ends, a plane whose normal
// points out of the scan): the implant fitted to the bone is not built beyond it, and the
// quality report counts no gap between the rim and the bone where the rim runs along it (no
// bone is known there).
TEST(BuildImplant, FittedToTheBoneItEndsWhereTheScanEnded) {
  const DefectCase& c = right_parietal_case();
  ImplantParams p;
  p.fit_to_bone_mm = 4.0;
  const ImplantResult whole = build_implant(c.markers, &c.defective, p);
  ASSERT_TRUE(whole.usable()) << whole.message;
  double lo = 1e9, hi = -1e9;
  for (auto vh : whole.mesh.vertices()) {
    lo = std::min<double>(lo, whole.mesh.point(vh)[1]);
    hi = std::max<double>(hi, whole.mesh.point(vh)[1]);
  }
  const double end = 0.5 * (lo + hi);  // the scan ends across the implant's middle
  p.scan_ends = {Plane{Eigen::Vector3d::UnitY(), end}};
  const ImplantResult cut = build_implant(c.markers, &c.defective, p);
  ASSERT_TRUE(cut.usable()) << cut.message;
  double widest = -1e9;
  for (auto vh : cut.mesh.vertices()) widest = std::max<double>(widest, cut.mesh.point(vh)[1]);
  // Voxels beyond the plane are cleared; the surface meshed from the blurred mask (σ 0.3 mm) on
  // its grid (0.25–0.45 mm) may reach a little past it.
  EXPECT_LT(widest, end + 1.0) << "built beyond the scan";
  EXPECT_GT(widest, end - 1.0) << "ends at the scan's end, not short of it";
  QualityParams q;
  const QualityReport without = check_implant(cut.mesh, &c.defective, q);
  q.scan_ends = p.scan_ends;
  const QualityReport with = check_implant(cut.mesh, &c.defective, q);
  EXPECT_GT(without.rim_gap_mm, 1.0) << "the cut side stands off the bone it never meets";
  EXPECT_LE(with.rim_gap_mm, kRimGapTargetMm) << "no gap counted along the scan's end";
}

// A material's edge clearance: over every 5° arc of the rim, the gap to the bone is the
// clearance to 0.2 mm (the measure), and the quality report says so; mass is volume
// times density.
TEST(BuildImplant, AMaterialsClearanceHoldsTheEdgeOffTheBoneOnEveryArc) {
  const DefectCase& c = right_parietal_case();
  for (double clearance : {0.5, 1.5, 3.0}) {
    SCOPED_TRACE(clearance);
    const Material m = peek_with(clearance, 0.0);
    const ImplantResult r = finished(m);
    ASSERT_TRUE(r.usable()) << r.message;
    const QualityReport q = check_implant(r.mesh, &c.defective, quality_params_for(m));
    ASSERT_TRUE(q.clearance_asked);
    EXPECT_GE(q.clearance_low_mm, -0.2);
    EXPECT_LE(q.clearance_high_mm, 0.2);
    EXPECT_NEAR(q.rim_gap_mm, clearance, 0.2);
    EXPECT_TRUE(q.printable) << (q.reasons.empty() ? "" : q.reasons[0]);
    EXPECT_NEAR(q.mass_g, q.volume_mm3 * 1.30e-3, 1e-9);
    EXPECT_EQ(q.material_name, "PEEK");
  }
}

// A burr hole at the edge of the opening, as SkullFix's cut-outs have at their corners: the edge
// markers run across its mouth, and the rays from the opening's centre towards its sides graze
// its walls. Fitted to the bone, the implant fills it up to the bone all round.
TEST(BuildImplant, FittedToTheBoneItFillsABurrHoleTheEdgeMarkersRunAcross) {
  const DefectCase& c = right_parietal_case();
  const Eigen::Vector3d center =
      test::head_surface_point(Eigen::Vector3d(0.7, 0.1, 0.7).normalized()) * 0.965;
  std::vector<const Marker*> outer;
  for (const Marker& m : c.markers)
    if (m.type == MarkerType::OuterEdge) outer.push_back(&m);
  ASSERT_GE(outer.size(), 2u);
  // Between two neighbouring edge markers, on the opening's sphere, halfway into the bone.
  const Eigen::Vector3d mouth = 0.5 * (outer[0]->position + outer[1]->position);
  const Eigen::Vector3d at = center + 25.0 * (0.965 * mouth - center).normalized();
  InjectDefectParams burr;
  burr.center = at;
  burr.size_mm = 11.0;
  burr.voxel_mm = 0.5;
  const InjectDefectResult holed = inject_defect(c.defective, burr);
  ASSERT_TRUE(holed.usable()) << holed.message;
  ASSERT_GT(holed.removed_volume_mm3, 50.0);
  const SurfaceLocator bone(holed.defective);
  ASSERT_GT(bone.closest(mouth).distance, 2.0) << "the burr hole opens the rim between them";
  ImplantParams p;
  p.fit_to_bone_mm = 4.0;
  const ImplantResult r = build_implant(c.markers, &holed.defective, p);
  ASSERT_TRUE(r.usable()) << r.message;
  const QualityReport q = check_implant(r.mesh, &holed.defective);
  EXPECT_LT(q.rim_gap_mm, 0.3);  // measured 0.10 mm
  EXPECT_LT(q.penetration_mm3, 5.0);
  EXPECT_TRUE(q.printable) << (q.reasons.empty() ? "" : q.reasons[0]);
  // Into the hole: the implant reaches the bone at the hole's far side (measured 0.10 mm; 0.85
  // mm when the rim stopped where the bone first came within half the margin, which the rim gap
  // over 5° arcs does not show: the implant touches the hole's sides).
  const SurfaceLocator implant(r.mesh);
  const Eigen::Vector3d far_side = bone.closest(at + 5.0 * (at - center).normalized()).point;
  EXPECT_LT(implant.closest(far_side).distance, 0.5);
}

// The build says where its time went: the shell, the whole fit, then the fit's own stages;
// the build's stages together no more than the whole.
TEST(BuildImplant, ItsStagesCarryTheFitsStages) {
  const ImplantResult r = finished(std::nullopt);
  ASSERT_TRUE(r.usable()) << r.message;
  ASSERT_GE(r.stage_seconds.size(), 4u);
  EXPECT_EQ(r.stage_seconds[0].first, "shell");
  EXPECT_EQ(r.stage_seconds[1].first, "fit");
  EXPECT_EQ(r.stage_seconds[2].first, "fit: voxels");
  // The fit's parts, then the check of its edge against the bone (fit_margin_search).
  EXPECT_EQ(r.stage_seconds[r.stage_seconds.size() - 2].first, "fit: meshing");
  EXPECT_EQ(r.stage_seconds.back().first, "fit margins");
  double whole = 0.0, parts = 0.0;
  for (const auto& [stage, seconds] : r.stage_seconds) {
    EXPECT_GE(seconds, 0.0) << stage;
    (stage.rfind("fit: ", 0) == 0 ? parts : whole) += seconds;
  }
  EXPECT_LE(whole, r.seconds + 1e-9);
  EXPECT_LE(parts, r.stage_seconds[1].second + 1e-9);
}

// The radii along rays from the head's centre through the middle of the opening: outer and
// inner surface of `implant`.
std::vector<std::pair<double, double>> radii(const SkullMesh& implant) {
  const SurfaceLocator loc(implant);
  const Eigen::Vector3d axis = Eigen::Vector3d(0.7, 0.1, 0.7).normalized();
  const Eigen::Vector3d e1 = axis.unitOrthogonal(), e2 = axis.cross(e1);
  std::vector<std::pair<double, double>> out;
  for (int i = -3; i <= 3; ++i)
    for (int j = -3; j <= 3; ++j) {
      const Eigen::Vector3d d = (axis + 0.04 * (i * e1 + j * e2)).normalized();
      const RayThroughBone h = [&] {
        RayThroughBone t;
        const auto in = loc.first_hit(Eigen::Vector3d::Zero(), 400.0 * d);
        const auto o = loc.first_hit(400.0 * d, Eigen::Vector3d::Zero());
        if (in) t.inner = in->point;
        if (o) t.outer = o->point;
        return t;
      }();
      if (h.inner && h.outer) out.emplace_back(h.outer->norm(), h.inner->norm());
    }
  return out;
}

// Under-contour: the outer surface is set that far below the one fitted to the markers, across
// the opening; the inner surface (the bone's thickness below) stays where it was (to 0.15 mm:
// the fit to the bone meshes both again from a 0.25 mm grid).
TEST(BuildImplant, UnderContourLowersTheOuterSurfaceOnly) {
  const ImplantResult flush = finished(peek_with(1.0, 0.0));
  const ImplantResult lowered = finished(peek_with(1.0, 0.8));
  ASSERT_TRUE(flush.usable() && lowered.usable()) << lowered.message;
  const auto a = radii(flush.mesh), b = radii(lowered.mesh);
  ASSERT_EQ(a.size(), 49u);
  ASSERT_EQ(b.size(), 49u);
  for (size_t k = 0; k < a.size(); ++k) {
    EXPECT_NEAR(a[k].first - b[k].first, 0.8, 0.15) << "outer, ray " << k;
    EXPECT_NEAR(a[k].second - b[k].second, 0.0, 0.15) << "inner, ray " << k;
  }
}

// A clearance zone over one side of the rim: the edge there keeps its 3 mm, the rest the
// material's 1 mm, every arc within 0.2 mm of what is asked where it lies.
TEST(BuildImplant, AClearanceZoneWidensTheGapAlongItsStretch) {
  const DefectCase& c = right_parietal_case();
  // The outer edge marker farthest along y: the zone is centred there.
  Eigen::Vector3d side = Eigen::Vector3d::Zero();
  for (const Marker& m : c.markers)
    if (m.type == MarkerType::OuterEdge && (side.isZero() || m.position.y() > side.y()))
      side = m.position;
  const std::vector<ClearanceZone> zones = {{side, 15.0, 3.0}};
  const Material m = peek_with(1.0, 0.0);
  const ImplantResult r = finished(m, zones);
  ASSERT_TRUE(r.usable()) << r.message;
  const QualityReport q = check_implant(r.mesh, &c.defective, quality_params_for(m, zones));
  EXPECT_GE(q.clearance_low_mm, -0.2);
  EXPECT_LE(q.clearance_high_mm, 0.2);
  EXPECT_NEAR(q.rim_gap_mm, 3.0, 0.2) << "the widest gap is the zone's";
  EXPECT_TRUE(q.printable) << (q.reasons.empty() ? "" : q.reasons[0]);
}

// A titanium plate laid on the bone: 1 mm thick over the opening, its underside the fitted outer
// surface, and over the rim onto the outer table.
TEST(BuildImplant, ATitaniumPlateLiesOnTheBoneOverTheOpening) {
  const DefectCase& c = right_parietal_case();
  const Material ti = *material_preset("titanium");
  const ImplantResult r = finished(ti);
  ASSERT_TRUE(r.usable()) << r.message;
  const QualityReport q = check_implant(r.mesh, &c.defective, quality_params_for(ti));
  EXPECT_TRUE(q.printable) << (q.reasons.empty() ? "" : q.reasons[0]);
  EXPECT_NEAR(q.thickness_median_mm, 1.0, 0.15);
  EXPECT_LT(q.penetration_mm3, 0.1) << "on the bone, not in it";
  EXPECT_NEAR(q.mass_g, q.volume_mm3 * 4.43e-3, 1e-9);
  // Across the opening it is the plate's thickness; its underside is the outer surface fitted
  // to the markers, the implant's without a material.
  const auto plate_radii = radii(r.mesh), flush = radii(finished(std::nullopt).mesh);
  ASSERT_EQ(plate_radii.size(), flush.size());
  for (size_t k = 0; k < flush.size(); ++k) {
    EXPECT_NEAR(plate_radii[k].first - plate_radii[k].second, 1.0, 0.2) << k;
    EXPECT_NEAR(plate_radii[k].second, flush[k].first, 0.3) << k;
  }
  // It covers the rim: every outer edge marker (on the outer table) lies under it.
  const SurfaceLocator plate(r.mesh);
  for (const Marker& m : c.markers)
    if (m.type == MarkerType::OuterEdge) {
      EXPECT_LT(plate.closest(m.position).distance, 0.5) << m.id;
    }
}

TEST(BuildImplant, FinishingWithoutTheFitToTheBoneIsRefused) {
  const DefectCase& c = right_parietal_case();
  ImplantParams p;
  p.material = peek_with(1.0, 0.0);
  const ImplantResult r = build_implant(c.markers, &c.defective, p);
  EXPECT_FALSE(r.usable());
  EXPECT_NE(r.message.find("fit to bone"), std::string::npos) << r.message;
  p.material->edge_clearance_mm = 5.0;
  p.fit_to_bone_mm = 4.0;
  EXPECT_NE(build_implant(c.markers, &c.defective, p).message.find("edge clearance must be"),
            std::string::npos);
}

// The preview while a marker is dragged: every finishing a full build would do is left out, so
// it builds where the finished implant builds, as the shell through the same markers with the
// material's thickness.
TEST(BuildImplant, TheLivePreviewIsTheShellThroughTheSameMarkers) {
  const DefectCase& c = right_parietal_case();
  ImplantParams full;
  full.fit_to_bone_mm = 4.0;
  full.material = peek_with(1.0, 0.5);
  full.material->thickness_mm = 4.0;
  full.clearance_zones.push_back(ClearanceZone{c.markers.front().position, 10.0, 2.0});
  full.tabs.automatic = true;
  full.perforations.pattern = true;
  const ImplantParams live = live_preview_params(full);
  EXPECT_EQ(live.fit_to_bone_mm, 0.0);
  EXPECT_TRUE(live.clearance_zones.empty());
  EXPECT_FALSE(live.tabs.any());
  EXPECT_FALSE(live.perforations.any());
  ASSERT_TRUE(live.material);
  EXPECT_EQ(live.material->thickness_mm, 4.0);
  EXPECT_EQ(live.material->min_thickness_mm, full.material->min_thickness_mm);
  const ImplantResult preview = build_implant(c.markers, &c.defective, live);
  ASSERT_TRUE(preview.usable()) << preview.message;
  EXPECT_TRUE(preview.watertight);
  ImplantParams shell;  // the same material, nothing to finish
  shell.material = peek_with(0.0, 0.0);
  shell.material->thickness_mm = 4.0;
  const ImplantResult plain = build_implant(c.markers, &c.defective, shell);
  ASSERT_TRUE(plain.usable()) << plain.message;
  EXPECT_NEAR(report_mesh(preview.mesh).volume_mm3, report_mesh(plain.mesh).volume_mm3, 1e-6);
}

// Tabs need the skull they lie on and the shell; a plate laid on the bone has none.
TEST(BuildImplant, TabsWithoutTheSkullOrOnAPlateAreRefused) {
  const DefectCase& c = right_parietal_case();
  ImplantParams p;
  p.fit_to_bone_mm = 4.0;
  p.tabs.automatic = true;
  EXPECT_NE(build_implant(c.markers, nullptr, p).message.find("give it"), std::string::npos);
  p.material = *material_preset("titanium");
  const ImplantResult r = build_implant(c.markers, &c.defective, p);
  EXPECT_FALSE(r.usable());
  EXPECT_NE(r.message.find("screwed through its own overlap"), std::string::npos) << r.message;
}

}  // namespace
}  // namespace cranioplan
