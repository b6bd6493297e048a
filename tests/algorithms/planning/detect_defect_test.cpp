#include "cranioplan/algorithms/planning/detect_defect.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>

#include "cranioplan/algorithms/geometry/surface_locator.h"
#include "cranioplan/algorithms/geometry/voxelize_mesh.h"
#include "cranioplan/algorithms/io/extract_bone_surface.h"
#include "cranioplan/algorithms/io/mesh_report.h"
#include "cranioplan/algorithms/quality/inject_defect.h"
#include "support/synthetic.h"

namespace cranioplan {
namespace {

double angle_deg(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::acos(std::clamp(a.normalized().dot(b.normalized()), -1.0, 1.0)) * 180.0 / M_PI;
}

// The plane z = -40 (normal −z: the scan ended below) within the box [-70, 70]² × [-40, 80].
ScanBorder lower_border() {
  ScanBorder b;
  b.normal = -Eigen::Vector3d::UnitZ();
  b.offset = 40.0;
  b.box_min = Eigen::Vector3d(-70, -70, -40);
  b.box_max = Eigen::Vector3d(70, 70, 80);
  return b;
}

// A two-table spherical shell around `center`: outer radius 70 mm, inner 64 mm (facing the
// cavity), on make_symmetric_head's triangles (`subdivisions` 4: 5,120 per table, edges about
// 6 mm; 5: 20,480, about 3 mm).
SkullMesh spherical_shell(const Eigen::Vector3d& center, int subdivisions) {
  const TriangleSoup unit = to_soup(test::make_symmetric_head(subdivisions));
  TriangleSoup soup = unit;
  for (auto& p : soup.vertices) p = center + 70.0 * p.normalized();
  const int n = static_cast<int>(soup.vertices.size());
  for (const auto& p : unit.vertices) soup.vertices.push_back(center + 64.0 * p.normalized());
  for (const auto& t : unit.triangles) soup.triangles.emplace_back(t[0] + n, t[2] + n, t[1] + n);
  return build_mesh(soup);
}

// The vault's centre is the inner table's sphere's, from a start anywhere in the cavity, on a
// coarse and a fine mesh of it, with a defect in it, and with everything below a cut gone (the
// rays there leave through the scan's end): it is sampled by direction, not by vertices.
TEST(VaultCenter, IsTheInnerTablesCentreHoweverTheShellIsMeshedOrCut) {
  const Eigen::Vector3d c(3.0, -5.0, 10.0);
  const Plane plane = Plane::through(c, Eigen::Vector3d::UnitX());
  const Eigen::Vector3d start = c + Eigen::Vector3d(0.0, 20.0, -15.0);
  const SkullMesh fine = spherical_shell(c, 5);
  const SkullMesh coarse = spherical_shell(c, 4);
  const SkullMesh holed =
      test::cut_hole(fine, c + 67.0 * Eigen::Vector3d(0.6, -0.5, 0.6).normalized(), 25.0);
  const SkullMesh cropped =
      test::cut_open(fine, c - Eigen::Vector3d(0, 0, 20), Eigen::Vector3d::UnitZ());
  ASSERT_LT(holed.n_faces(), fine.n_faces());
  ASSERT_LT(cropped.n_faces(), fine.n_faces());
  for (const SkullMesh* mesh : {&fine, &coarse, &holed, &cropped}) {
    double radius = 0.0;
    const auto center = vault_center(SurfaceLocator(*mesh), plane, start, &radius);
    ASSERT_TRUE(center.has_value());
    EXPECT_LT((*center - c).norm(), 0.3) << center->transpose();
    EXPECT_NEAR(radius, 64.0, 0.5);
    EXPECT_NEAR(plane.signed_distance(*center), 0.0, 1e-9);
  }
  // A flat plate has no vault's centre: its hits lie in a plane.
  const SkullMesh plate = build_mesh(test::box_soup({-50, -50, 0}, {50, 50, 5}));
  const Eigen::Vector3d below(0, 0, -20);
  EXPECT_FALSE(
      vault_center(SurfaceLocator(plate), Plane::through(below, Eigen::Vector3d::UnitX()), below)
          .has_value());
}

TEST(ScanBorder, IsReachedByRaysThatMeetItsPlaneWithinTheBox) {
  const ScanBorder b = lower_border();
  const Eigen::Vector3d o = Eigen::Vector3d::Zero();
  EXPECT_TRUE(b.reached_by(o, -Eigen::Vector3d::UnitZ()));                // at (0,0,-40)
  EXPECT_TRUE(b.reached_by(o, Eigen::Vector3d(1, 0, -1).normalized()));   // at x = 40
  EXPECT_FALSE(b.reached_by(o, Eigen::Vector3d(2, 0, -1).normalized()));  // x = 80: out
  EXPECT_FALSE(b.reached_by(o, Eigen::Vector3d::UnitZ()));                // away from it
  EXPECT_FALSE(b.reached_by(o, Eigen::Vector3d::UnitX()));                // parallel
  EXPECT_FALSE(b.reached_by(Eigen::Vector3d(0, 0, -50), -Eigen::Vector3d::UnitZ()));  // behind
}

// A cap's border is reached only within its outline, not in the corners of its box: a ray
// through an opening beside the cap (a defect low on the side) meets the plane there.
TEST(ScanBorder, ACapIsReachedOnlyWithinItsOutline) {
  ScanBorder b = lower_border();
  // A diamond in z = -40, counter-clockwise seen along the outward normal (-z).
  b.outline = {{0, 60, -40}, {60, 0, -40}, {0, -60, -40}, {-60, 0, -40}};
  const Eigen::Vector3d o = Eigen::Vector3d::Zero();
  EXPECT_TRUE(b.reached_by(o, -Eigen::Vector3d::UnitZ()));                    // at (0, 0)
  EXPECT_TRUE(b.reached_by(o, Eigen::Vector3d(0.5, 0.25, -1).normalized()));  // at (20, 10)
  EXPECT_FALSE(b.reached_by(o, Eigen::Vector3d(1, 1, -1).normalized()));      // (40, 40): a corner
  b.outline.clear();
  EXPECT_TRUE(b.reached_by(o, Eigen::Vector3d(1, 1, -1).normalized())) << "within the box";
}

TEST(ScanBorder, AHeadOpenWhereTheScanEndedHasOneBorderThere) {
  const SkullMesh head = test::make_symmetric_head(5);
  EXPECT_TRUE(scan_borders(report_mesh(head)).empty()) << "a closed surface has no border";
  const SkullMesh open =
      test::cut_open(head, Eigen::Vector3d(0, 0, -30.0), Eigen::Vector3d::UnitZ());
  const MeshReport report = report_mesh(open);
  const std::vector<ScanBorder> borders = scan_borders(report);
  ASSERT_EQ(borders.size(), 1u);
  EXPECT_LT(angle_deg(borders[0].normal, -Eigen::Vector3d::UnitZ()), 1e-9);
  // The cut keeps whole faces above the plane: the border lies within a face's size above it.
  EXPECT_NEAR(-borders[0].offset, -30.0, 6.0);
  EXPECT_GE(-borders[0].offset, -30.0);
  EXPECT_EQ(borders[0].box_min, report.bbox_min);
  EXPECT_EQ(borders[0].box_max, report.bbox_max);
}

// A spherical skull (tables 70 and 76 mm from the centre) with a round defect 20° wide about
// `d0`, and below it (within 60° of −z about `d0`, from 20° to 34° off it) a frontal sinus: an
// inner table 70–73 mm, air, and a front wall 84–87 mm, so that a ray there crosses 17 mm of
// bone; walls 3–4° wide close it but on the defect's side, which opens into it. Meshed from a
// 1 mm mask, as a CT's bone is.
SkullMesh skull_with_a_sinus_under_its_defect(const Eigen::Vector3d& d0) {
  const VoxelGrid g =
      VoxelGrid::covering(Eigen::Vector3d::Constant(-92.0), Eigen::Vector3d::Constant(92.0), 1.0);
  const Eigen::Vector3d down = (-Eigen::Vector3d::UnitZ() + d0.z() * d0).normalized();
  std::vector<uint8_t> bone(g.size(), 0);
  for (int k = 0; k < g.dims[2]; ++k)
    for (int j = 0; j < g.dims[1]; ++j)
      for (int i = 0; i < g.dims[0]; ++i) {
        const Eigen::Vector3d p = g.center(i, j, k);
        const double r = p.norm();
        if (r < 69.0 || r > 88.0) continue;
        const Eigen::Vector3d u = p / r;
        const double off = angle_deg(u, d0);
        if (off < 20.0) continue;  // the defect
        const double side = angle_deg(u - u.dot(d0) * d0, down);
        const bool sinus = off <= 34.0 && side <= 60.0;
        const bool walls = off <= 37.0 && side <= 64.0;  // close it but on the defect's side
        bone[g.index(i, j, k)] = sinus   ? (r >= 70.0 && r <= 73.0) || (r >= 84.0 && r <= 87.0)
                                 : walls ? r >= 70.0 && r <= 87.0
                                         : r >= 70.0 && r <= 76.0;
      }
  ExtractBoneSurfaceParams mask;
  mask.threshold = 0.5;
  return extract_bone_surface(mask_volume(bone, g), mask).mesh;
}

// A ray through both walls of a frontal sinus crosses 15–20 mm of bone, and the rim of a defect
// that opens into the sinus is that bone. With rays that may cross 20 mm (the default) the rim
// runs along the defect's edge over the sinus; with 15 mm no ray there crosses bone, and the
// rim is not seen there.
TEST(DetectDefect, TheRimRunsAlongAFrontalSinusTheDefectOpensInto) {
  const Eigen::Vector3d d0 = Eigen::Vector3d(0.8, 0.3, 0.15).normalized();
  const Eigen::Vector3d down = (-Eigen::Vector3d::UnitZ() + d0.z() * d0).normalized();
  const SkullMesh skull = skull_with_a_sinus_under_its_defect(d0);
  const SurfaceLocator locator(skull);
  // The rim points over the sinus (within 50° of its middle, clear of its sides).
  const auto over_the_sinus = [&](const DefectRegion& r) {
    std::vector<double> off;
    for (const Eigen::Vector3d& p : r.outer_rim) {
      const Eigen::Vector3d u = p.normalized();
      if (angle_deg(u - u.dot(d0) * d0, down) <= 50.0) off.push_back(angle_deg(u, d0));
    }
    return off;
  };
  const auto unseen_mm = [](const DefectRegion& r) {
    double sum = 0.0;
    for (const RimStretch& s : r.unseen_rim) sum += s.length_mm();
    return sum;
  };
  DetectDefectParams params;
  ASSERT_EQ(params.max_thickness_mm, 20.0);
  const DefectRegion found = detect_defect(skull, locator, Eigen::Vector3d::Zero(), params);
  ASSERT_TRUE(found.found()) << found.message;
  EXPECT_LT(angle_deg(found.axis, d0), 3.0);
  const std::vector<double> along = over_the_sinus(found);
  EXPECT_GE(along.size(), 4u) << "the rim is seen along the sinus";
  for (double off : along) EXPECT_LT(off, 23.0) << "at the defect's edge (20°), not beyond";
  EXPECT_LT(unseen_mm(found), 10.0);
  // The sinus spans about 55 mm of the rim: with 15 mm no ray there crosses bone, and all but
  // a stray ray at the edge of its walls leave it unseen by the rays.
  params.max_thickness_mm = 15.0;
  params.trace_rim_on_bone = false;
  const DefectRegion thin = detect_defect(skull, locator, Eigen::Vector3d::Zero(), params);
  ASSERT_TRUE(thin.found()) << thin.message;
  EXPECT_LE(over_the_sinus(thin).size(), 1u);
  EXPECT_GT(unseen_mm(thin), 30.0);
  RecordProperty("unseen_rim_mm_at_15", std::to_string(unseen_mm(thin)));
  RecordProperty("unseen_rim_mm_at_20", std::to_string(unseen_mm(found)));
  // Traced on the bone, the rim runs along the sinus's front wall all the same.
  params.trace_rim_on_bone = true;
  const DefectRegion traced = detect_defect(skull, locator, Eigen::Vector3d::Zero(), params);
  ASSERT_TRUE(traced.found()) << traced.message;
  EXPECT_TRUE(traced.rim_traced);
  const std::vector<double> traced_along = over_the_sinus(traced);
  EXPECT_GE(traced_along.size(), 4u);
  for (double off : traced_along) EXPECT_LT(off, 23.0);
  EXPECT_EQ(unseen_mm(traced), 0.0);
}

// A skull mesh's load report gives its borders to a detection that has none; borders already
// given, or no report (a skull from a volume), are left as they are.
TEST(ScanBorder, AreTakenFromTheLoadsReportUnlessGiven) {
  const SkullMesh open = test::cut_open(test::make_symmetric_head(5), Eigen::Vector3d(0, 0, -30.0),
                                        Eigen::Vector3d::UnitZ());
  const std::optional<MeshReport> report = report_mesh(open);
  DetectDefectParams taken;
  take_scan_borders(taken, report);
  ASSERT_TRUE(taken.scan_borders.has_value());
  ASSERT_EQ(taken.scan_borders->size(), 1u);
  EXPECT_EQ(taken.scan_borders->front().normal, scan_borders(*report).front().normal);
  EXPECT_EQ(taken.scan_borders->front().offset, scan_borders(*report).front().offset);
  DetectDefectParams given;
  given.scan_borders.emplace();
  take_scan_borders(given, report);
  EXPECT_TRUE(given.scan_borders->empty()) << "the caller's borders are kept";
  DetectDefectParams volume;
  take_scan_borders(volume, std::nullopt);
  EXPECT_FALSE(volume.scan_borders.has_value()) << "left to be found from the mesh";
}

// A thick head with a known defect, open on its right side where the scan (or an exporter's
// crop) ended. Without the scan's border a deep cut is the largest opening and is planned; with
// it the defect is the only opening, and a defect that reaches into the cut is found as itself,
// not merged with the cut (its rays leave past the cut's extent).
struct OpenHead {
  SkullMesh skull;
  Eigen::Vector3d defect_direction;
};

SkullMesh head_with_defect(const Eigen::Vector3d& direction) {
  const SkullMesh intact = test::make_thick_head(0.93, 1.0);
  InjectDefectParams p;
  p.center = test::head_surface_point(direction.normalized()) * 0.965;
  p.size_mm = 55;
  p.voxel_mm = 1.0;
  return inject_defect(intact, p).defective;
}

OpenHead open_head_with_defect(const Eigen::Vector3d& direction, double right_x,
                               const Eigen::Vector3d& cut_normal = Eigen::Vector3d::UnitX()) {
  return {test::cut_open(head_with_defect(direction), Eigen::Vector3d(right_x, 0, 0),
                         cut_normal.normalized()),
          direction.normalized()};
}

// The same scan, meshed by an importer that pads the volume: closed, a flat cap across the bone
// where the scan ended.
OpenHead padded_head_with_defect(const Eigen::Vector3d& direction, double right_x) {
  return {test::scanned_padded(head_with_defect(direction), Eigen::Vector3d(right_x, 0, 0),
                               Eigen::Vector3d::UnitX()),
          direction.normalized()};
}

DefectRegion detect(const SkullMesh& skull, bool with_borders) {
  DetectDefectParams params;
  // The head's own frame, its midsagittal plane x = 0 (as detect_defect_near_plane gives it).
  params.frame = skull_frame(skull, Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitX());
  if (with_borders) params.scan_borders = scan_borders(report_mesh(skull));
  return detect_defect(skull, SurfaceLocator(skull), Eigen::Vector3d::Zero(), params);
}

TEST(DetectDefect, TheScansCutIsNeverTheDefect) {
  // Cut 20 mm right of the midline: the opening it leaves is far larger than the defect.
  const OpenHead h = open_head_with_defect(Eigen::Vector3d(0.7, 0.1, 0.7), -20.0);
  const DefectRegion without = detect(h.skull, false);
  ASSERT_TRUE(without.found()) << without.message;
  EXPECT_LT(angle_deg(without.axis, -Eigen::Vector3d::UnitX()), 10.0) << "the cut, planned";
  EXPECT_EQ(without.other_openings, 1) << without.message;
  const DefectRegion with = detect(h.skull, true);
  ASSERT_TRUE(with.found()) << with.message;
  EXPECT_LT(angle_deg(with.axis, h.defect_direction), 10.0);
  EXPECT_EQ(with.other_openings, 0) << with.message;
}

// The same with the cut tilted 35° (no axis's plane): its border is found in its own plane
// and the cut is still never planned.
TEST(DetectDefect, AnObliqueCutIsNeverTheDefect) {
  const Eigen::Vector3d tilted(std::cos(35 * M_PI / 180), 0.0, std::sin(35 * M_PI / 180));
  const OpenHead h = open_head_with_defect(Eigen::Vector3d(0.7, 0.1, 0.7), -20.0, tilted);
  const std::vector<ScanBorder> borders = scan_borders(report_mesh(h.skull));
  ASSERT_EQ(borders.size(), 1u);
  EXPECT_LT(angle_deg(borders[0].normal, -tilted), 2.0);
  const DefectRegion without = detect(h.skull, false);
  ASSERT_TRUE(without.found()) << without.message;
  EXPECT_GT(angle_deg(without.axis, h.defect_direction), 30.0) << "the cut, planned";
  const DefectRegion with = detect(h.skull, true);
  ASSERT_TRUE(with.found()) << with.message;
  EXPECT_LT(angle_deg(with.axis, h.defect_direction), 10.0);
  EXPECT_EQ(with.other_openings, 0) << with.message;
}

// A defect on the right, high on the head, that the scan's cut runs through (its right part).
const Eigen::Vector3d kDefectAtTheCut = Eigen::Vector3d(-0.5, 0.1, 0.85).normalized();
double cut_through_the_defect_x() { return test::head_surface_point(kDefectAtTheCut).x() - 12.0; }

// Without the scan's border the defect is merged with the head's inside seen through the cut;
// with it, the defect is found as itself, smaller than the two together, and most of it is
// kept: only the rays that meet the cut's plane within the bone's cross-section there (the
// outline of the cut's loops, or of the cap) are the scan's end.
void expect_the_defect_not_the_cut(const OpenHead& h) {
  const DefectRegion without = detect(h.skull, false);
  ASSERT_TRUE(without.found()) << without.message;
  const DefectRegion with = detect(h.skull, true);
  ASSERT_TRUE(with.found()) << with.message;
  EXPECT_LT(angle_deg(with.axis, h.defect_direction), 20.0) << with.message;
  EXPECT_GT(angle_deg(without.axis, h.defect_direction), 20.0) << without.message;
  EXPECT_GT(with.area_mm2, 300.0);
  EXPECT_LT(with.area_mm2, 0.5 * without.area_mm2);
  const DefectRegion uncut = detect(head_with_defect(kDefectAtTheCut), false);
  ASSERT_TRUE(uncut.found()) << uncut.message;
  EXPECT_GT(with.area_mm2, 0.8 * uncut.area_mm2);
  EXPECT_LT(with.area_mm2, 1.02 * uncut.area_mm2);
}

TEST(DetectDefect, ADefectThatReachesTheScansCutIsStillADefect) {
  expect_the_defect_not_the_cut(open_head_with_defect(kDefectAtTheCut, cut_through_the_defect_x()));
}

// Closed by the padding instead of open: the cut's opening is the head's inside seen through
// the cap's ring of bone. Without the scan's border it is planned; with the cap as the border,
// the defect is the only opening.
TEST(DetectDefect, AScanEndClosedByPaddingIsNeverTheDefect) {
  const OpenHead h = padded_head_with_defect(Eigen::Vector3d(0.7, 0.1, 0.7), -20.0);
  const MeshReport report = report_mesh(h.skull);
  ASSERT_TRUE(report.watertight);
  ASSERT_EQ(report.caps.size(), 1u);
  EXPECT_EQ(report.caps[0].border, "right");
  const DefectRegion without = detect(h.skull, false);
  ASSERT_TRUE(without.found()) << without.message;
  EXPECT_LT(angle_deg(without.axis, -Eigen::Vector3d::UnitX()), 10.0) << "the cut, planned";
  const DefectRegion with = detect(h.skull, true);
  ASSERT_TRUE(with.found()) << with.message;
  EXPECT_LT(angle_deg(with.axis, h.defect_direction), 10.0);
  EXPECT_EQ(with.other_openings, 0) << with.message;
}

// A defect that the padded cut runs through (its right part) is still the defect, and is not
// merged with the head's inside seen through the cap: rays through it that meet the cap's plane
// within the cap's extent are taken for the scan's end, as with an open cut.
TEST(DetectDefect, ADefectThatReachesAPaddedScanEndIsStillADefect) {
  expect_the_defect_not_the_cut(
      padded_head_with_defect(kDefectAtTheCut, cut_through_the_defect_x()));
}

// Where the opening runs into the scan's end no bone edges it, and no ray sees a rim there:
// the rim is traced on the bone and, across the scan's end, along the border's plane where the
// table would cross it. The opening is planned as itself, its rim seen all round, the plane goes
// with it (the implant ends there) and the message says the bone beyond the scan is unknown.
void expect_the_rim_along_the_scans_end(const OpenHead& h) {
  const std::vector<ScanBorder> borders = scan_borders(report_mesh(h.skull));
  ASSERT_EQ(borders.size(), 1u);
  const DefectRegion with = detect(h.skull, true);
  ASSERT_TRUE(with.found()) << with.message;
  EXPECT_LT(angle_deg(with.axis, h.defect_direction), 20.0) << with.message;
  ASSERT_TRUE(with.rim_traced) << with.message;
  ASSERT_EQ(with.scan_ends.size(), 1u) << with.message;
  EXPECT_LT(angle_deg(with.scan_ends[0].normal, borders[0].normal), 1.0);
  double along = 0.0;
  for (const RimStretch& st : with.at_scan_border) {
    along += st.length_mm();
    for (const Eigen::Vector3d& p : {st.from, st.to})
      EXPECT_NEAR(borders[0].normal.dot(p), borders[0].offset, 2.0);
  }
  // The cut runs 12 mm inside the 55 mm defect's centre: a chord of about 2·√(27.5² − 12²).
  EXPECT_GT(along, 30.0) << with.message;
  EXPECT_NE(with.message.find("the bone beyond the scan is unknown"), std::string::npos)
      << with.message;
  // The rim's points along the scan's end lie on its plane, where the intact head's outer table
  // crosses it (within the head's curvature between the seeds the table's distance is read
  // from).
  const SkullMesh intact = test::make_thick_head(0.93, 1.0);
  const SurfaceLocator whole(intact);
  int on_plane = 0;
  double worst = 0.0;
  for (const Eigen::Vector3d& p : with.outer_rim)
    if (std::abs(borders[0].normal.dot(p) - borders[0].offset) < 0.5) {
      ++on_plane;
      const SurfaceLocator::Closest near = whole.closest(p);
      worst = std::max(worst, near.distance);
      EXPECT_GT(whole.face_normal(near.face).dot(near.point - with.center), 0.0)
          << "nearest the outer table, not the inner";
    }
  ::testing::Test::RecordProperty("worst_off_the_table_mm", std::to_string(worst));
  EXPECT_LT(worst, 2.0);
  EXPECT_GT(on_plane, 20);
}

TEST(DetectDefect, AnOpeningIntoAnOpenScansEndIsTracedAlongItsPlane) {
  expect_the_rim_along_the_scans_end(
      open_head_with_defect(kDefectAtTheCut, cut_through_the_defect_x()));
}

TEST(DetectDefect, AnOpeningIntoAPaddedScansEndIsTracedAlongItsPlane) {
  expect_the_rim_along_the_scans_end(
      padded_head_with_defect(kDefectAtTheCut, cut_through_the_defect_x()));
}

// A point to choose the opening: one in its direction plans it without a note; one on intact
// bone far from it still plans the only opening, and the message says no opening lies towards
// the point (a cut that did not go through would otherwise plan another opening unsaid).
TEST(DetectDefect, APointFarFromEveryOpeningIsSaidToMissIt) {
  const test::ThickHeadDefect& c = test::thick_head_defect();
  ASSERT_TRUE(c.defect.found()) << c.defect.message;
  const SurfaceLocator bone(c.defective);
  DetectDefectParams towards;
  towards.near = c.defect.center + 80.0 * c.defect.axis;
  const DefectRegion hit = detect_defect(c.defective, bone, c.defect.center, towards);
  ASSERT_TRUE(hit.found());
  EXPECT_LT(hit.near_miss_deg, 1.0);
  EXPECT_EQ(hit.message.find("no opening lies towards"), std::string::npos) << hit.message;
  DetectDefectParams away;
  away.near = c.defect.center - 80.0 * c.defect.axis;
  const DefectRegion miss = detect_defect(c.defective, bone, c.defect.center, away);
  ASSERT_TRUE(miss.found());
  EXPECT_GT(miss.near_miss_deg, 90.0);
  EXPECT_NE(miss.message.find("no opening lies towards the point given: the nearest, planned, is"),
            std::string::npos)
      << miss.message;
  EXPECT_EQ(miss.hole_directions.size(), hit.hole_directions.size()) << "the same opening";
}

}  // namespace
}  // namespace cranioplan
