#include "cranioplan/algorithms/implant/fixation_tabs.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <functional>
#include <vector>

#include "cranioplan/algorithms/geometry/surface_locator.h"
#include "cranioplan/algorithms/geometry/voxelize_mesh.h"
#include "cranioplan/algorithms/io/extract_bone_surface.h"
#include "cranioplan/algorithms/io/mesh_report.h"
#include "cranioplan/algorithms/quality/check_implant.h"
#include "support/synthetic.h"

namespace cranioplan {
namespace {

// A flat bone 6 mm thick (z 0 to `top`) over 100 × 100 mm with a 40 × 40 mm opening (x and y
// 30 to 70), and an implant filling the opening with a 1 mm gap all round, both meshed from
// masks on a 0.25 mm grid as the planner's surfaces are (each surface halfway between the last
// voxel centre inside and the first outside: the bone's top at `top` − 0.125 mm, its bottom at
// 0.125 mm); the skull's inside lies below.
SkullMesh solid_of(const std::function<bool(const Eigen::Vector3d&)>& inside,
                   const Eigen::Vector3d& lo, const Eigen::Vector3d& hi) {
  const VoxelGrid g = VoxelGrid::covering(lo, hi, 0.25, 3);
  std::vector<uint8_t> mask(g.size());
  for (int k = 0; k < g.dims[2]; ++k)
    for (int j = 0; j < g.dims[1]; ++j)
      for (int i = 0; i < g.dims[0]; ++i) mask[g.index(i, j, k)] = inside(g.center(i, j, k));
  ExtractBoneSurfaceParams surface;
  surface.threshold = 0.5;
  return extract_bone_surface(mask_volume(mask, g), surface).mesh;
}
SkullMesh bone(double top = 6.0) {
  return solid_of(
      [top](const Eigen::Vector3d& p) {
        const bool slab = p.z() > 0 && p.z() < top;
        const bool hole = p.x() > 30 && p.x() < 70 && p.y() > 30 && p.y() < 70;
        return slab && !hole;
      },
      {0, 0, 0}, {100, 100, top});
}
SkullMesh plug(double top = 6.0) {
  return solid_of(
      [top](const Eigen::Vector3d& p) {
        return p.z() > 0 && p.z() < top && p.x() > 31 && p.x() < 69 && p.y() > 31 && p.y() < 69;
      },
      {31, 31, 0}, {69, 69, top});
}
const Eigen::Vector3d kInside(50, 50, -60);
constexpr double kTop = 5.875, kBoneMm = 5.75;  // the meshed bone's top and thickness

// The quality report of an implant with tabs on `skull`, the plug's 1 mm gap all round asked as
// its edge clearance.
QualityReport report_with_tabs(const TabResult& r, const SkullMesh& skull) {
  QualityParams q;
  q.edge_clearance_mm = 1.0;
  q.tabs = r.tabs;
  return check_implant(r.mesh, &skull, q);
}

// Evenly placed tabs on a flat rim: one per 40 mm of the 152 mm edge, each lying on the bone
// (its underside within 0.2 mm of it), reaching its length beyond the edge, 2 mm thick, with a
// screw hole through; tabs and plate one closed, manifold solid with a tunnel per screw, which
// the quality report passes.
TEST(FixationTabs, EvenlyPlacedTabsLieOnTheBoneWithTheirScrewsThrough) {
  const SkullMesh skull = bone(), implant = plug();
  const SurfaceLocator on_bone(skull);
  TabParams p = resolved(TabParams{}, std::nan(""));
  p.automatic = true;
  EXPECT_DOUBLE_EQ(p.width_mm, 6.0);
  EXPECT_DOUBLE_EQ(p.thickness_mm, 2.0);  // 1 mm under a 0.6 mm countersink, + 0.4
  const TabResult r = add_fixation_tabs(implant, on_bone, kInside, p);
  ASSERT_TRUE(r.usable()) << r.message;
  EXPECT_NEAR(r.rim_length_mm, 4 * 38.0, 6.0);
  ASSERT_EQ(r.tabs.size(), 4u);
  const SurfaceLocator self(r.mesh);
  for (const Tab& t : r.tabs) {
    EXPECT_NEAR(t.normal.z(), 1.0, 1e-3);
    EXPECT_NEAR(t.rim.z(), kTop, 0.3);
    EXPECT_LT(std::abs(t.outward.z()), 1e-3);
    ASSERT_EQ(t.screws.size(), 1u);
    EXPECT_NEAR(t.screws[0].center.z(), kTop + 0.05 + 2.0, 0.01) << "on the tab's top";
    EXPECT_TRUE(hole_goes_through(self, t.screws[0]));
    EXPECT_NEAR(t.bone_mm, kBoneMm, 0.01);
    const double gap = tab_gap(self, on_bone, t);
    EXPECT_GE(gap, -0.05);
    EXPECT_LE(gap, 0.2);
    // The top 2 mm above the underside, over the bone.
    const Eigen::Vector3d on = t.rim + (t.length_mm - 1.0) * t.outward;
    const auto top = self.first_hit(on + 10.0 * t.normal, on);
    ASSERT_TRUE(top.has_value());
    EXPECT_NEAR(top->point.z(), kTop + 0.05 + 2.0, 0.1);
    // The tab's far end lies its length beyond the implant's edge (at 69 or 31).
    const Eigen::Vector3d end = t.rim + (t.length_mm + 0.3) * t.outward,
                          before = t.rim + (t.length_mm - 0.3) * t.outward;
    EXPECT_FALSE(self.first_hit(end + Eigen::Vector3d(0, 0, 10), end));
    EXPECT_TRUE(self.first_hit(before + Eigen::Vector3d(0, 0, 10), before));
  }
  const MeshReport rep = report_mesh(r.mesh);
  EXPECT_TRUE(rep.watertight);
  EXPECT_EQ(rep.nonmanifold_edges, 0);
  EXPECT_EQ(rep.pieces, 1);
  EXPECT_EQ(test::genus(r.mesh), 4) << "a tunnel per screw";
  const QualityReport report = report_with_tabs(r, skull);
  EXPECT_TRUE(report.printable) << (report.reasons.empty() ? "" : report.reasons.front());
  EXPECT_EQ(report.tabs, 4);
  EXPECT_EQ(report.screws_blocked, 0);
  EXPECT_LE(report.tab_gap_mm, 0.2);
}

// The bone of bone() with a pit 1.5 mm across and `depth` mm deep in its outer table, 1.4 to
// 2.9 mm beyond the opening's edge at y = 70, from each x of `pits_from_x` (by default 1 to
// 2.5 mm to the side of x = 50: under a tab at the middle of that side), between the points at
// which the even placement looks at the bone (a fragment's surface uneven at a finer scale than
// they see), wider than a crack the tab's underside bridges.
SkullMesh pitted_bone(double depth, const std::vector<double>& pits_from_x = {51.0}) {
  return solid_of(
      [=](const Eigen::Vector3d& p) {
        const bool hole = p.x() > 30 && p.x() < 70 && p.y() > 30 && p.y() < 70;
        bool pit = false;
        for (const double x0 : pits_from_x)
          pit = pit || (p.x() > x0 && p.x() < x0 + 1.5 && p.y() > 71.4 && p.y() < 72.9);
        return p.z() > 0 && p.z() < (pit ? 6.0 - depth : 6.0) && !hole;
      },
      {0, 0, 0}, {100, 100, 6});
}

// Evenly placed, the tab at the middle of the pitted side stands 2.7 mm off the bone over the
// pit, and placed once (as plans saved before build_implant 12 were made) the quality report
// refuses it by name. Measured on the joined mesh as the report measures it, that tab is
// placed again away from the pit: the message says one tab moved, every tab rests on the bone
// and the plan is printable.
TEST(FixationTabs, AnEvenlyPlacedTabThatWouldStandOffTheBoneIsPlacedAgain) {
  const SkullMesh skull = pitted_bone(3.0), implant = plug();
  const SurfaceLocator on_bone(skull);
  TabParams p = resolved(TabParams{}, std::nan(""));
  p.automatic = true;
  TabParams once = p;
  once.keep_on_bone = false;
  const Eigen::Vector3d pit(51.75, 72.15, kTop);
  // Whether a tab's footprint (its length beyond the rim, its width across) covers the pit.
  auto over_pit = [&](const Tab& t) {
    const Eigen::Vector3d d = pit - t.rim;
    const double along = d.dot(t.outward), across = d.dot(t.normal.cross(t.outward));
    return along > -1.0 && along < t.length_mm + 1.0 && std::abs(across) < 0.5 * t.width_mm + 1.0;
  };

  const TabResult placed_once = add_fixation_tabs(implant, on_bone, kInside, once);
  ASSERT_TRUE(placed_once.usable()) << placed_once.message;
  ASSERT_EQ(placed_once.tabs.size(), 4u);
  const SurfaceLocator joined_once(placed_once.mesh);
  int off = 0;
  for (const Tab& t : placed_once.tabs) {
    const double gap = tab_gap(joined_once, on_bone, t);
    off += gap > 0.2;
    EXPECT_EQ(gap > 0.2, over_pit(t)) << t.rim.transpose() << ": " << gap << " mm";
  }
  EXPECT_EQ(off, 1) << "the case has the tab the rule moves";
  const QualityReport refused = report_with_tabs(placed_once, skull);
  EXPECT_FALSE(refused.printable);
  EXPECT_GT(refused.tab_gap_mm, 2.0);
  bool named = false;
  for (const std::string& why : refused.reasons)
    named = named || why.find("stands up to") != std::string::npos;
  EXPECT_TRUE(named);

  const TabResult r = add_fixation_tabs(implant, on_bone, kInside, p);
  ASSERT_TRUE(r.usable()) << r.message;
  ASSERT_EQ(r.tabs.size(), 4u);
  EXPECT_NE(r.message.find("1 tab moved along the rim"), std::string::npos) << r.message;
  const SurfaceLocator joined(r.mesh);
  for (const Tab& t : r.tabs) {
    EXPECT_FALSE(over_pit(t)) << t.rim.transpose();
    EXPECT_LE(tab_gap(joined, on_bone, t), 0.2) << t.rim.transpose();
  }
  const QualityReport report = report_with_tabs(r, skull);
  EXPECT_TRUE(report.printable) << (report.reasons.empty() ? "" : report.reasons.front());
  EXPECT_LE(report.tab_gap_mm, 0.2);
}

// A second pit where the first tab placed again would land (under the side's tab at x = 44):
// the second round moves that one too. Two tabs moved, none over a pit, all four on the bone.
TEST(FixationTabs, ATabPlacedAgainOntoAnotherPitIsPlacedOnceMore) {
  const SkullMesh skull = pitted_bone(3.0, {51.0, 44.5}), implant = plug();
  const SurfaceLocator on_bone(skull);
  TabParams p = resolved(TabParams{}, std::nan(""));
  p.automatic = true;
  const TabResult r = add_fixation_tabs(implant, on_bone, kInside, p);
  ASSERT_TRUE(r.usable()) << r.message;
  ASSERT_EQ(r.tabs.size(), 4u);
  EXPECT_NE(r.message.find("2 tabs moved along the rim from where they would stand off"),
            std::string::npos)
      << r.message;
  const SurfaceLocator joined(r.mesh);
  for (const Tab& t : r.tabs) EXPECT_LE(tab_gap(joined, on_bone, t), 0.2) << t.rim.transpose();
  const QualityReport report = report_with_tabs(r, skull);
  EXPECT_TRUE(report.printable) << (report.reasons.empty() ? "" : report.reasons.front());
  EXPECT_LE(report.tab_gap_mm, 0.2);
}

// The crossings of the surface along a line, from `from` to `to` (heights along z).
std::vector<double> crossings_along(const SurfaceLocator& s, const Eigen::Vector3d& from,
                                    const Eigen::Vector3d& to) {
  std::vector<double> z;
  for (const SurfaceLocator::Hit& hit : s.hits_along(from, to)) z.push_back(hit.point.z());
  return z;
}

// An implant whose outer surface lies 2.5 mm below the bone's outer table (within the 3 mm
// tab's reach): over the implant the tab's underside lies on it, so tab and implant are one
// solid, without a gap under the tab's inner end, and the quality report passes it. With the
// underside kept 1.5 mm below the outer table, as plans saved before build_implant 9 are made
// on replay, the tab stands 1 mm over the implant and touches it nowhere: it is refused by
// name, not left out of the mesh (its largest piece) while the result counts it.
TEST(FixationTabs, OverALowerImplantTheTabLiesOnIt) {
  const SkullMesh skull = bone(), implant = plug(3.5);
  const SurfaceLocator on_bone(skull);
  TabParams p = resolved(TabParams{}, std::nan(""));
  p.thickness_mm = 3.0;
  p.positions = {Eigen::Vector3d(50, 75, 6)};
  const TabResult r = add_fixation_tabs(implant, on_bone, kInside, p);
  ASSERT_TRUE(r.usable()) << r.message;
  ASSERT_EQ(r.tabs.size(), 1u);
  // Down a line 1.5 mm inside the implant's edge, under the tab's inner end: the tab's top and
  // the implant's bottom, nothing between.
  const SurfaceLocator self(r.mesh);
  const std::vector<double> crossings =
      crossings_along(self, Eigen::Vector3d(50, 67.5, 20), Eigen::Vector3d(50, 67.5, -5));
  ASSERT_EQ(crossings.size(), 2u);
  // The tab's top at least its thickness over the implant's (3.375 mm, meshed), at most over
  // the bone's.
  EXPECT_GE(crossings[0], 3.375 + 3.0 - 0.1) << "the tab's top";
  EXPECT_LE(crossings[0], kTop + 0.05 + 3.0 + 0.1) << "the tab's top";
  EXPECT_NEAR(crossings[1], 0.125, 0.01) << "the implant's bottom";
  const QualityReport report = report_with_tabs(r, skull);
  EXPECT_TRUE(report.printable) << (report.reasons.empty() ? "" : report.reasons.front());
  EXPECT_LE(report.tab_gap_mm, 0.2);

  p.follow_implant = false;
  const TabResult before = add_fixation_tabs(implant, on_bone, kInside, p);
  EXPECT_FALSE(before.usable());
  EXPECT_TRUE(before.tabs.empty());
  EXPECT_NE(before.message.find("tab 1 does not join the implant"), std::string::npos)
      << before.message;
}

// An implant whose outer edge is rounded over 4 mm (a quarter circle from z 6 down to 2 at its
// wall, as a fitted implant's edge is): under the tab the implant drops away faster than the
// bridging of narrow gaps allows (0.3 mm within 0.6 mm). The tab's underside comes down onto
// the rounded edge — tab and implant one solid, nothing between them down lines through the
// rounding up to 0.6 mm from its wall (nearer, within the union's 0.2 mm grid) — and the gap at
// the edge keeps its clearance below the plug. As plans saved before
// build_implant 10 are made, the tab stands over the rounding with air under it.
TEST(FixationTabs, OverARoundedImplantEdgeTheTabComesDownOntoIt) {
  const SkullMesh skull = bone();
  const SkullMesh implant = solid_of(
      [](const Eigen::Vector3d& p) {
        if (!(p.z() > 0 && p.x() > 31 && p.x() < 69 && p.y() > 31 && p.y() < 69)) return false;
        const double over = std::max(0.0, p.y() - 65.0);  // into the rounding at y = 69
        return p.z() < 2.0 + std::sqrt(std::max(0.0, 16.0 - over * over));
      },
      {31, 31, 0}, {69, 69, 6});
  const SurfaceLocator on_bone(skull);
  TabParams p = resolved(TabParams{}, std::nan(""));
  p.thickness_mm = 3.0;
  p.positions = {Eigen::Vector3d(50, 75, 6)};
  for (const bool on_edge : {true, false}) {
    SCOPED_TRACE(on_edge ? "onto the edge" : "as before build_implant 10");
    p.on_implant_edge = on_edge;
    const TabResult r = add_fixation_tabs(implant, on_bone, kInside, p);
    ASSERT_TRUE(r.usable()) << r.message;
    const SurfaceLocator self(r.mesh);
    int with_air = 0;
    for (const double y : {67.6, 68.0, 68.4})
      for (const double x : {48.0, 50.0, 52.0}) {
        const std::vector<double> z =
            crossings_along(self, Eigen::Vector3d(x, y, 20), Eigen::Vector3d(x, y, -5));
        ASSERT_GE(z.size(), 2u);
        with_air += z.size() > 2;
      }
    if (on_edge) {
      EXPECT_EQ(with_air, 0) << "the tab and the implant are one solid under the tab";
      // In the gap at the edge (y 69 to 70), below the plug (1.5 mm under the outer table),
      // nothing was added.
      for (const double x : {48.0, 50.0, 52.0})
        EXPECT_TRUE(
            crossings_along(self, Eigen::Vector3d(x, 69.5, 3.8), Eigen::Vector3d(x, 69.5, 0.5))
                .empty());
      const QualityReport report = report_with_tabs(r, skull);
      EXPECT_TRUE(report.printable) << (report.reasons.empty() ? "" : report.reasons.front());
      EXPECT_EQ(report.penetration_mm3, 0.0);
    } else {
      EXPECT_GT(with_air, 0) << "the tab stood over the rounding";
    }
  }
}

// The midline: with the plane x = 50 and 10 mm asked, no tab comes nearer it; the tabs that
// would lie across it move along the rim.
TEST(FixationTabs, TheEvenPlacementKeepsOffTheMidline) {
  const SkullMesh skull = bone(), implant = plug();
  const SurfaceLocator on_bone(skull);
  TabParams p = resolved(TabParams{}, std::nan(""));
  p.automatic = true;
  p.midline = Plane{Eigen::Vector3d::UnitX(), 50.0};
  const TabResult r = add_fixation_tabs(implant, on_bone, kInside, p);
  ASSERT_TRUE(r.usable()) << r.message;
  ASSERT_GE(r.tabs.size(), 3u);
  for (const Tab& t : r.tabs) {
    EXPECT_GE(t.midline_mm, 10.0);
    for (const Hole& s : t.screws) EXPECT_GE(std::abs(s.center.x() - 50.0), 10.0);
  }
}

// Thin bone: asked for screws into bone 7 mm thick on a 6 mm bone, no place is found and the
// implant is left as it was.
TEST(FixationTabs, NoPlaceOnBoneThinnerThanAskedIsRefused) {
  const SkullMesh skull = bone(), implant = plug();
  const SurfaceLocator on_bone(skull);
  TabParams p = resolved(TabParams{}, std::nan(""));
  p.automatic = true;
  p.min_bone_mm = 7.0;
  const TabResult r = add_fixation_tabs(implant, on_bone, kInside, p);
  EXPECT_FALSE(r.usable());
  EXPECT_NE(r.message.find("7"), std::string::npos) << r.message;
  EXPECT_EQ(r.mesh.n_faces(), implant.n_faces());
}

// Meshed into a mesh the caller gives, the tabs are what the result would hold (the result's
// own mesh empty); refused, the given mesh holds the implant as it came.
TEST(FixationTabs, MeshedIntoAGivenMeshAsTheyWouldBeReturned) {
  const SkullMesh skull = bone(), implant = plug();
  const SurfaceLocator on_bone(skull);
  TabParams p = resolved(TabParams{}, std::nan(""));
  p.automatic = true;
  const TabResult returned = add_fixation_tabs(implant, on_bone, kInside, p);
  ASSERT_TRUE(returned.usable()) << returned.message;
  SkullMesh into = plug();
  const TabResult given = add_fixation_tabs(implant, on_bone, kInside, p, into);
  ASSERT_TRUE(given.usable()) << given.message;
  EXPECT_EQ(given.mesh.n_faces(), 0u);
  EXPECT_EQ(given.tabs.size(), returned.tabs.size());
  EXPECT_EQ(to_soup(into).vertices, to_soup(returned.mesh).vertices);
  EXPECT_EQ(to_soup(into).triangles, to_soup(returned.mesh).triangles);
  p.min_bone_mm = 7.0;
  EXPECT_FALSE(add_fixation_tabs(implant, on_bone, kInside, p, into).usable());
  EXPECT_EQ(to_soup(into).triangles, to_soup(implant).triangles);
}

// A tab the user puts: at the rim point nearest the point given, reaching away from the
// implant there.
TEST(FixationTabs, AUsersTabGoesToTheNearestRimPoint) {
  const SkullMesh skull = bone(), implant = plug();
  const SurfaceLocator on_bone(skull);
  TabParams p = resolved(TabParams{}, std::nan(""));
  p.positions = {Eigen::Vector3d(45, 95, 6)};
  const TabResult r = add_fixation_tabs(implant, on_bone, kInside, p);
  ASSERT_TRUE(r.usable()) << r.message;
  ASSERT_EQ(r.tabs.size(), 1u);
  EXPECT_TRUE(r.tabs[0].added);
  EXPECT_NEAR(r.tabs[0].rim.y(), 69.0, 0.5);
  EXPECT_NEAR(r.tabs[0].rim.x(), 45.0, 2.0);
  EXPECT_NEAR(r.tabs[0].outward.y(), 1.0, 0.05);
  EXPECT_EQ(test::genus(r.mesh), 1);
  // Two tabs closer than their width overlap: refused, naming them.
  p.positions = {Eigen::Vector3d(45, 95, 6), Eigen::Vector3d(48, 95, 6)};
  const TabResult both = add_fixation_tabs(implant, on_bone, kInside, p);
  EXPECT_FALSE(both.usable());
  EXPECT_NE(both.message.find("tabs 1 and 2 overlap"), std::string::npos) << both.message;
}

// The quality report's tab checks fail on constructed bad cases: a tab standing off the bone
// (the bone 0.5 mm lower than the tabs were laid on), screws into bone thinner than asked, a
// tab nearer the midline than asked.
TEST(FixationTabs, TheQualityReportRefusesATabOffTheBone) {
  const SkullMesh skull = bone(), implant = plug();
  const SurfaceLocator on_bone(skull);
  TabParams p = resolved(TabParams{}, std::nan(""));
  p.positions = {Eigen::Vector3d(50, 95, 6)};
  const TabResult r = add_fixation_tabs(implant, on_bone, kInside, p);
  ASSERT_TRUE(r.usable()) << r.message;
  QualityParams q;
  q.tabs = r.tabs;
  const SkullMesh lower = bone(5.5);
  const QualityReport off = check_implant(r.mesh, &lower, q);
  EXPECT_FALSE(off.printable);
  EXPECT_NEAR(off.tab_gap_mm, 0.55, 0.1);
  bool said = false;
  for (const std::string& s : off.reasons)
    said = said || s.find("tab 1 stands") != std::string::npos;
  EXPECT_TRUE(said);

  q.tab_min_bone_mm = 8.0;
  q.tab_midline_mm = 10.0;
  q.tabs[0].midline_mm = 4.0;
  const QualityReport near = check_implant(r.mesh, &skull, q);
  EXPECT_FALSE(near.printable);
  int found = 0;
  for (const std::string& s : near.reasons)
    found += s.find("tab 1's screws go into bone") != std::string::npos ||
             s.find("4.0 mm from the midsagittal plane") != std::string::npos;
  EXPECT_EQ(found, 2);
}

// The bone of bone() with a crack `width` mm wide and 1 mm deep across y = 69 + 4.5 (from
// x 40 to 60, under a tab at x = 50), and, with `rounded`, its outer table's edge at the
// opening rounded over 1.5 mm (a quarter circle, as a cut's edge often is).
SkullMesh cracked_bone(double width, bool rounded) {
  return solid_of(
      [=](const Eigen::Vector3d& p) {
        const bool hole = p.x() > 30 && p.x() < 70 && p.y() > 30 && p.y() < 70;
        double top = 6.0;
        const double from_edge = p.y() - 70.0;  // beyond the opening's edge at y = 70
        if (rounded && from_edge >= 0 && from_edge < 1.5 && p.x() > 30 && p.x() < 70)
          top -= 1.5 - std::sqrt(1.5 * 1.5 - (1.5 - from_edge) * (1.5 - from_edge));
        const bool crack =
            p.x() > 40 && p.x() < 60 && std::abs(p.y() - 73.5) < 0.5 * width && p.z() > 5.0;
        return p.z() > 0 && p.z() < top && !hole && !crack;
      },
      {0, 0, 0}, {100, 100, 6});
}

// The report's tab gap counts where the tab rests on the bone as it was made to: it bridges a
// crack narrower than 1.2 mm (the underside over it up to 0.3 mm below the bone beside it),
// beside a square edge of the bone and a rounded one; a stretch wider than that with the tab
// off the bone is still refused. (The rule for the first 0.5 mm beyond the bone's edge is met
// on the sample's PMMA plan, where the rounding's facets face the tab here and there.)
TEST(FixationTabs, TheTabGapCountsWhereTheTabRestsOnTheBone) {
  const SkullMesh implant = plug();
  for (const bool rounded : {false, true}) {
    SCOPED_TRACE(rounded ? "the bone's edge rounded" : "the bone's edge square");
    const SkullMesh skull = cracked_bone(0.75, rounded);
    const SurfaceLocator on_bone(skull);
    TabParams p = resolved(TabParams{}, std::nan(""));
    p.positions = {Eigen::Vector3d(50, 95, 6)};
    const TabResult r = add_fixation_tabs(implant, on_bone, kInside, p);
    ASSERT_TRUE(r.usable()) << r.message;
    // The underside spans the crack: over its middle it stands more than the limit above the
    // crack's floor, and on the bone beside it.
    const SurfaceLocator self(r.mesh);
    const auto underside = [&](double y) {
      const std::vector<double> z =
          crossings_along(self, Eigen::Vector3d(50, y, 4.0), Eigen::Vector3d(50, y, 20));
      return z.empty() ? 0.0 : z[0];
    };
    const auto bone_top = [&](double y) {
      const auto hit = on_bone.first_hit(Eigen::Vector3d(50, y, 20), Eigen::Vector3d(50, y, 0));
      return hit ? hit->point.z() : 0.0;
    };
    EXPECT_NEAR(bone_top(73.5), 5.0, 0.15) << "the crack's floor";
    EXPECT_GT(underside(73.5) - bone_top(73.5), 0.4) << "the crack is bridged";
    EXPECT_NEAR(underside(76.0) - bone_top(76.0), 0.05, 0.1) << "on the bone beside it";
    const QualityReport report = report_with_tabs(r, skull);
    EXPECT_TRUE(report.printable) << (report.reasons.empty() ? "" : report.reasons.front());
    EXPECT_LE(report.tab_gap_mm, 0.2);
    EXPECT_GE(report.tab_gap_mm, -0.05);
    // The same tab over a crack 3 mm wide (the bone there as before, the tab as made on the
    // narrow one): it stands off the crack's floor over more than twice the bridging's reach.
    const SkullMesh wide = cracked_bone(3.0, rounded);
    const QualityReport off = report_with_tabs(r, wide);
    EXPECT_FALSE(off.printable);
    EXPECT_GT(off.tab_gap_mm, 0.5);
  }
}

TEST(FixationTabs, ParametersOutOfRangeAreNamed) {
  TabParams p;
  p.automatic = true;
  EXPECT_EQ(tab_problem(p), "");
  p.screws = 2;
  EXPECT_NE(tab_problem(resolved(p, 2.0)).find("for two screws"), std::string::npos);
  p.length_mm = 20.0;
  EXPECT_EQ(tab_problem(resolved(p, 2.0)), "");
  p.screws = 3;
  EXPECT_EQ(tab_problem(p), "the tabs' number of screws must be 1 to 2 (3 given)");
  p.screws = 1;
  p.thickness_mm = 0.6;
  p.countersink_diameter_mm = 3.4;
  EXPECT_NE(tab_problem(p).find("countersink"), std::string::npos);
  p = TabParams{};
  p.count = 13;
  EXPECT_NE(tab_problem(p).find("count"), std::string::npos);
  p = TabParams{};
  p.positions = {Eigen::Vector3d(std::nan(""), 0, 0)};
  EXPECT_EQ(tab_problem(p), "a tab's position is not a point");
}

}  // namespace
}  // namespace cranioplan
