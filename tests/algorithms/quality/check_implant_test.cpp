#include "cranioplan/algorithms/quality/check_implant.h"

#include <gtest/gtest.h>

#include <cstdio>

#include "cranioplan/algorithms/geometry/surface_locator.h"
#include "cranioplan/algorithms/geometry/voxelize_mesh.h"
#include "cranioplan/algorithms/io/extract_bone_surface.h"
#include "support/synthetic.h"

namespace cranioplan {
namespace {

SkullMesh box(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi) {
  return build_mesh(test::box_soup(lo, hi));
}

bool has_reason(const QualityReport& q, const std::string& part) {
  for (const auto& r : q.reasons)
    if (r.find(part) != std::string::npos) return true;
  return false;
}

bool judged_thin(const QualityReport& q) {
  return has_reason(q, "thinner than") || has_reason(q, "nowhere is the implant");
}

TEST(CheckImplant, ThicknessVolumeAndReasonsOnKnownBoxes) {
  // A 30 × 30 × 4 mm plate: thickness 4 mm everywhere on its large faces.
  const QualityReport plate = check_implant(box({0, 0, 0}, {30, 30, 4}), nullptr);
  EXPECT_TRUE(plate.watertight);
  EXPECT_TRUE(plate.outward);
  EXPECT_NEAR(plate.volume_mm3, 3600.0, 1e-9);
  EXPECT_NEAR(plate.thickness_min_mm, 4.0, 1e-3);
  EXPECT_NEAR(plate.thickness_max_mm, 4.0, 1e-3);
  EXPECT_TRUE(plate.printable) << (plate.reasons.empty() ? "" : plate.reasons[0]);

  // Too thin to print, and overlapping a "skull" box by 30 × 30 × 0.2 mm = 180 mm³ (measured on
  // 0.25 mm voxels: within one voxel layer, 225 mm³).
  const SkullMesh thin = box({0, 0, 0}, {30, 30, 0.5});
  const SkullMesh skull = box({-10, -10, 0.3}, {40, 40, 10});
  const QualityReport q = check_implant(thin, &skull);
  EXPECT_FALSE(q.printable);
  EXPECT_NEAR(q.penetration_mm3, 180.0, 60.0);
  EXPECT_TRUE(has_reason(q, "nowhere is the implant 1.00 mm thick")) << q.reasons[0];
  EXPECT_TRUE(has_reason(q, "overlap the skull"));
}

// A 4 mm spherical cap (radii 60 and 64 mm, 50° around +z) meshed from a 0.5 mm voxel mask, as
// trimmed implants are: the staircase tilts facets by up to 45° from the plate, and their
// normals run along it (on the sample's implant up to 27 mm). The thickness is still 4 mm.
TEST(CheckImplant, ThicknessOfAVoxelMeshedCurvedPlateIsItsThickness) {
  const VoxelGrid grid = VoxelGrid::covering({-60, -60, 30}, {60, 60, 66}, 0.5);
  std::vector<uint8_t> cap(grid.size());
  for (int k = 0; k < grid.dims[2]; ++k)
    for (int j = 0; j < grid.dims[1]; ++j)
      for (int i = 0; i < grid.dims[0]; ++i) {
        const Eigen::Vector3d p = grid.center(i, j, k);
        const double r = p.norm();
        cap[grid.index(i, j, k)] = r >= 60 && r <= 64 && p.z() >= r * std::cos(50 * M_PI / 180);
      }
  const SkullMesh plate = extract_bone_surface(mask_volume(cap, grid)).mesh;
  ASSERT_GT(plate.n_faces(), 10000u);
  const QualityReport q = check_implant(plate, nullptr);
  EXPECT_TRUE(q.watertight);
  EXPECT_NEAR(q.thickness_median_mm, 4.0, 0.5);
  EXPECT_GT(q.thickness_max_mm, 4.0);
  EXPECT_LT(q.thickness_max_mm, 5.5) << "a normal that ran along the plate was taken for its "
                                        "thickness";
}

// A wedge lying on the bone: the cross-section (x, z) is the quadrilateral (0,0), (L,0), (L,H),
// (H/tan θ, H), extruded over y in [−w, w], so its only sharp edge is the apex of angle θ at
// x = 0, resting on the bone's top face z = 0 (lifted by `lift`).
SkullMesh wedge(double angle_deg, double lift) {
  const double L = 30.0, H = 6.0, w = 10.0, x_top = H / std::tan(angle_deg * M_PI / 180.0);
  const std::vector<Eigen::Vector2d> section = {{0, 0}, {L, 0}, {L, H}, {x_top, H}};
  TriangleSoup s;
  for (double y : {-w, w})
    for (const auto& p : section) s.vertices.push_back({p.x(), y, p.y() + lift});
  s.triangles = {{0, 1, 2}, {0, 2, 3}, {4, 6, 5}, {4, 7, 6}};  // caps
  for (int i = 0; i < 4; ++i) {
    const int j = (i + 1) % 4;
    s.triangles.push_back({i, i + 4, j + 4});
    s.triangles.push_back({i, j + 4, j});
  }
  SkullMesh m = build_mesh(s);
  if (signed_volume(m) < 0) flip_orientation(m);
  return m;
}

// Thin material is the wedge's tip: a ball of 1 mm fits at r / sin(θ/2) from the apex, so the
// tapered edge reaches r / sin(θ/2) − r beyond the thick part (0.96 mm at 40°, 3.3 mm at 15°).
// On 0.25 mm voxels the last of the tip, thinner than about half a voxel, has no voxel: the
// measure falls short by up to h / tan θ.
TEST(CheckImplant, ATaperedEdgeOnTheBoneIsPrintableUpToItsWidth) {
  const SkullMesh bone = box({-50, -50, -10}, {50, 50, 0});
  const double r = 0.5, h = 0.25;
  auto expect_reach = [&](double reach, double angle_deg) {
    const double a = angle_deg * M_PI / 180, truth = r / std::sin(a / 2) - r;
    EXPECT_GT(reach, truth - h / std::tan(a) - 0.2) << angle_deg << "°";
    EXPECT_LT(reach, truth + 0.3) << angle_deg << "°";
  };
  const QualityReport blunt = check_implant(wedge(40, 0), &bone);
  expect_reach(blunt.taper_reach_mm, 40);
  EXPECT_LT(blunt.corner_reach_mm, 0.8);
  EXPECT_GT(blunt.thin_volume_mm3, 0.0);
  EXPECT_FALSE(judged_thin(blunt)) << blunt.reasons[0];

  const QualityReport sharp = check_implant(wedge(15, 0), &bone);
  expect_reach(sharp.taper_reach_mm, 15);
  EXPECT_TRUE(has_reason(sharp, "its edge stays thinner than 1.00 mm"));
  // Just over a limit that reads the same to a tenth, the measure is said finely enough not to
  // read as the limit itself ("for 1.2 mm; may be 1.2 mm").
  {
    QualityParams close;
    close.max_taper_mm = std::round(blunt.taper_reach_mm * 10.0) / 10.0 - 0.049;
    ASSERT_LT(close.max_taper_mm, blunt.taper_reach_mm);
    const QualityReport over = check_implant(wedge(40, 0), &bone, close);
    ASSERT_FALSE(over.reasons.empty());
    const std::string& said = over.reasons.front();
    const size_t from = said.find(" for ") + 5, to = said.find(" mm (a tapered");
    ASSERT_NE(to, std::string::npos) << said;
    const std::string value = said.substr(from, to - from);
    char limit[16];
    std::snprintf(limit, sizeof(limit), "%.1f", close.max_taper_mm);
    EXPECT_NE(value, limit) << said;
    EXPECT_GT(std::stod(value), close.max_taper_mm) << said;
    EXPECT_NEAR(std::stod(value), over.taper_reach_mm, 0.006) << said;
  }
  // A 10° wedge's taper (5.2 mm) reaches past the distances the check first takes (as far as
  // the widest taper and corner allowed, and a millimetre): it is measured in full.
  const QualityReport sharper = check_implant(wedge(10, 0), &bone);
  EXPECT_NEAR(sharper.taper_reach_mm, r / std::sin(5.0 * M_PI / 180) - r, 0.4);

  // A 30° wedge: on the bone its taper (1.4 mm) is printable; 5 mm above the bone its thin tip
  // is a sharp corner, not an edge resting on the bone (at most 0.8 mm: 45° and more).
  const QualityReport resting = check_implant(wedge(30, 0), &bone);
  expect_reach(resting.taper_reach_mm, 30);
  EXPECT_FALSE(judged_thin(resting)) << resting.reasons[0];
  // Without the skull the same taper cannot be told from a corner, and the report says so.
  EXPECT_TRUE(has_reason(check_implant(wedge(30, 0), nullptr), "without the skull"));
  const QualityReport lifted = check_implant(wedge(30, 5), &bone);
  expect_reach(lifted.corner_reach_mm, 30);
  EXPECT_NEAR(lifted.thin_off_bone_mm3, lifted.thin_volume_mm3, 1e-9);
  EXPECT_TRUE(has_reason(lifted, "away from the bone it is thinner than 1.00 mm"));

  // A box's 90° corners are not thin material.
  const QualityReport plate = check_implant(box({0, 0, 0.1}, {30, 30, 4.1}), &bone);
  EXPECT_LT(plate.corner_reach_mm, 0.8);
  EXPECT_FALSE(judged_thin(plate));
}

// The rim gap's arcs slide: a gap 5° wide or more is found wherever it lies, and the same
// points turned by any angle, or listed in another order, give the same gap. (Over 72 fixed 5°
// sectors beginning at the mesh's first wall vertex, the gap below, 6.5° wide, hides from
// sectors beginning at 0°, each of which also holds a vertex on the bone, and reordering the
// vertices moves the sectors.)
TEST(CheckImplant, TheRimGapIsTheWorstArcWhereverItLies) {
  const double deg = M_PI / 180;
  std::vector<double> angle, distance;
  for (int k = 0; k < 720; ++k) {  // a vertex every 0.5°, 0.1 mm from the bone
    angle.push_back(k * 0.5 * deg);
    distance.push_back(0.1);
  }
  // Over 7° from 101.25° (14 vertices) the wall stands 1.2 mm off, and 1.5 mm in the middle.
  for (int k = 203; k < 217; ++k) distance[k] = k == 210 ? 1.5 : 1.2;
  EXPECT_DOUBLE_EQ(worst_arc_gap(angle, distance, 5 * deg), 1.2);
  // Where: a point of the stretch whose distance is the gap.
  size_t where = 0;
  EXPECT_DOUBLE_EQ(worst_arc_gap(angle, distance, 5 * deg, &where), 1.2);
  EXPECT_GE(where, 203u);
  EXPECT_LT(where, 217u);
  EXPECT_DOUBLE_EQ(distance[where], 1.2);
  double fixed_sectors = 0.0;  // the old measure, sectors beginning at 0°
  for (int s = 0; s < 72; ++s) {
    double nearest = 1e9;
    for (size_t k = 0; k < angle.size(); ++k)
      if (static_cast<int>(angle[k] / (5 * deg) + 1e-9) == s)
        nearest = std::min(nearest, distance[k]);
    fixed_sectors = std::max(fixed_sectors, nearest);
  }
  EXPECT_DOUBLE_EQ(fixed_sectors, 0.1) << "the sectors 100°–105° and 105°–110° reach the bone";
  for (double turn : {0.0, 0.3, 17.0, 103.0, -250.0}) {
    std::vector<double> turned = angle;
    for (double& a : turned) a += turn * deg;
    EXPECT_NEAR(worst_arc_gap(turned, distance, 5 * deg), 1.2, 1e-12) << turn;
  }
  // Listed in another order.
  std::vector<size_t> order(angle.size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = (i * 389) % order.size();
  std::vector<double> a2, d2;
  for (size_t i : order) {
    a2.push_back(angle[i]);
    d2.push_back(distance[i]);
  }
  EXPECT_DOUBLE_EQ(worst_arc_gap(a2, d2, 5 * deg), 1.2);
  // Narrower than the gap's core, the arc finds the 1.5 mm vertex alone only where no other
  // vertex shares its arc: with vertices 0.5° apart an arc of 0.4° can hold it alone.
  EXPECT_DOUBLE_EQ(worst_arc_gap(angle, distance, 0.4 * deg), 1.5);
  // Without points, no gap; one point is its own gap.
  EXPECT_EQ(worst_arc_gap({}, {}, 5 * deg), 0.0);
  EXPECT_DOUBLE_EQ(worst_arc_gap({2.0}, {0.7}, 5 * deg), 0.7);
}

// What a person is shown of a rim gap (the wizard's ball, the report's row): the worst arc when
// it is over the 0.5 mm automatic plans aim for; with a clearance asked, the arc furthest beyond
// it when that is over 0.5 mm (a gap the clearance asked for is no fault).
TEST(CheckImplant, TheRimGapToMarkIsOverTheTargetOrBeyondTheClearance) {
  QualityReport meets;
  meets.rim_gap_mm = 0.09;
  meets.rim_gap_at = Eigen::Vector3d(1, 2, 3);
  EXPECT_FALSE(rim_gap_to_mark(meets));
  QualityReport off = meets;
  off.rim_gap_mm = 1.07;
  ASSERT_TRUE(rim_gap_to_mark(off));
  EXPECT_EQ(*rim_gap_to_mark(off), Eigen::Vector3d(1, 2, 3));
  QualityReport asked = off;  // 1.07 mm is what a clearance of 1 mm asks for
  asked.clearance_asked = true;
  asked.clearance_high_mm = 0.07;
  asked.clearance_high_at = Eigen::Vector3d(4, 5, 6);
  EXPECT_FALSE(rim_gap_to_mark(asked));
  asked.clearance_high_mm = 0.8;
  ASSERT_TRUE(rim_gap_to_mark(asked));
  EXPECT_EQ(*rim_gap_to_mark(asked), Eigen::Vector3d(4, 5, 6));
}

// Two 20 × 20 × 5 mm plates of bone, 10 mm apart along x (cut faces at x = 20 and 30).
SkullMesh two_plates() {
  TriangleSoup plates = test::box_soup({0, 0, 0}, {20, 20, 5});
  const TriangleSoup right = test::box_soup({30, 0, 0}, {50, 20, 5});
  const int n = static_cast<int>(plates.vertices.size());
  plates.vertices.insert(plates.vertices.end(), right.vertices.begin(), right.vertices.end());
  for (auto t : right.triangles) plates.triangles.push_back({t[0] + n, t[1] + n, t[2] + n});
  return build_mesh(plates);
}

// A clearance asked and not kept, on a constructed case: bone plates with a 10 mm gap, an
// implant 0.3 mm off the left cut face and 2.5 mm off the right. Asked 1 mm, the left edge
// would not go in and the right leaves a gap 1.5 mm too wide: not printable, for both reasons.
// Asked nothing, only the 2.5 mm gap is judged, as before. Its mass is volume × density.
TEST(CheckImplant, AClearanceAskedButNotKeptIsNotPrintable) {
  const SkullMesh bone = two_plates();
  const SkullMesh implant = box({20.3, 0, 0}, {27.5, 20, 5});
  QualityParams asked;
  asked.edge_clearance_mm = 1.0;
  asked.density_g_cm3 = 1.3;
  const QualityReport q = check_implant(implant, &bone, asked);
  EXPECT_TRUE(q.clearance_asked);
  EXPECT_NEAR(q.clearance_low_mm, -0.7, 0.05);
  EXPECT_NEAR(q.clearance_high_mm, 1.5, 0.05);
  EXPECT_FALSE(q.printable);
  EXPECT_TRUE(has_reason(q, "nearer the bone than the clearance asked"));
  EXPECT_TRUE(has_reason(q, "wider than the clearance asked"));
  EXPECT_NEAR(q.mass_g, 7.2 * 20 * 5 * 1.3e-3, 1e-6);

  const QualityReport plain = check_implant(implant, &bone);
  EXPECT_FALSE(plain.clearance_asked);
  EXPECT_NEAR(plain.rim_gap_mm, 2.5, 0.05);
  EXPECT_TRUE(has_reason(plain, "gap of 2.50 mm between the rim and the bone"));
  // Where: on the implant's right wall (x = 27.5), facing the right plate's cut face (x = 30),
  // and named in the reason.
  ASSERT_TRUE(plain.rim_gap_at && plain.rim_gap_bone);
  EXPECT_NEAR(plain.rim_gap_at->x(), 27.5, 1e-6);
  EXPECT_NEAR(plain.rim_gap_bone->x(), 30.0, 1e-6);
  EXPECT_NEAR((*plain.rim_gap_bone - *plain.rim_gap_at).norm(), plain.rim_gap_mm, 1e-9);
  char at[64];
  std::snprintf(at, sizeof(at), " at (%.1f, %.1f, %.1f) mm", plain.rim_gap_at->x(),
                plain.rim_gap_at->y(), plain.rim_gap_at->z());
  EXPECT_TRUE(has_reason(plain, at)) << at;
  ASSERT_TRUE(q.clearance_high_at);
  EXPECT_NEAR(q.clearance_high_at->x(), 27.5, 1e-6) << "the right side is 1.5 mm too wide";
  EXPECT_FALSE(has_reason(plain, "clearance"));
  EXPECT_EQ(plain.mass_g, 0.0);

  // A zone over the right cut face asking 2.5 mm there: that side is now as asked.
  asked.clearance_zones = {{Eigen::Vector3d(35, 10, 2.5), 12.0, 2.5}};
  const QualityReport zoned = check_implant(implant, &bone, asked);
  EXPECT_LE(zoned.clearance_high_mm, 0.2);
  EXPECT_FALSE(has_reason(zoned, "wider than the clearance asked"));
  EXPECT_TRUE(has_reason(zoned, "nearer the bone than the clearance asked"));
}

// The fit to the bone judges its edge with rim_gap (fit_margin_search), the report with its
// own pass over the same side wall: the two agree, gap and place, with and without a clearance
// (the implant 2.5 mm from the right plate's cut face, 0.3 mm from the left one's).
TEST(CheckImplant, TheFitMeasuresItsEdgeAsTheReportDoes) {
  const SkullMesh bone = two_plates();
  const SurfaceLocator locator(bone);
  const SkullMesh implant = box({20.3, 0, 0}, {27.5, 20, 5});
  const QualityReport plain = check_implant(implant, &bone);
  const RimGap gap = rim_gap(implant, locator, false, 0.0, {});
  EXPECT_NEAR(gap.mm, 2.5, 0.05);
  EXPECT_DOUBLE_EQ(gap.mm, plain.rim_gap_mm);
  ASSERT_TRUE(gap.at && plain.rim_gap_at);
  EXPECT_EQ(*gap.at, *plain.rim_gap_at);
  QualityParams asked;
  asked.edge_clearance_mm = 1.0;
  const QualityReport q = check_implant(implant, &bone, asked);
  const RimGap excess = rim_gap(implant, locator, true, 1.0, {});
  EXPECT_NEAR(excess.mm, 1.5, 0.05) << "2.5 mm where 1 mm was asked";
  EXPECT_DOUBLE_EQ(excess.mm, q.clearance_high_mm);
  ASSERT_TRUE(excess.at && q.clearance_high_at);
  EXPECT_EQ(*excess.at, *q.clearance_high_at);
  // No side wall, no gap.
  EXPECT_EQ(rim_gap(SkullMesh{}, locator, false, 0.0, {}).mm, 0.0);
}

}  // namespace
}  // namespace cranioplan
