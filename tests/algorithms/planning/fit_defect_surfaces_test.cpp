#include "cranioplan/algorithms/planning/fit_defect_surfaces.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <vector>

#include "cranioplan/algorithms/geometry/point_index.h"
#include "cranioplan/algorithms/geometry/surface_locator.h"
#include "cranioplan/algorithms/quality/inject_defect.h"
#include "support/synthetic.h"

namespace cranioplan {
namespace {

using Case = test::ThickHeadDefect;
const Case& the_case() { return test::thick_head_defect(); }

struct Errors {
  double outer_median = 0, outer_max = 0, inner_median = 0, inner_max = 0;
  size_t count = 0;
};

// Fitted points against the intact skull, ray by ray through the opening.
Errors errors_against_truth(const DefectSurfaces& s) {
  const Case& c = the_case();
  const SurfaceLocator truth(c.intact);
  std::vector<double> outer, inner;
  for (const auto& d : c.defect.hole_directions) {
    const auto fitted = s.at(d);
    const RayThroughBone t = cast_through_bone(truth, c.defect.center, d, 400.0, 0.5, 15.0);
    if (!fitted || !t.paired) continue;
    outer.push_back((fitted->first - *t.outer).norm());
    inner.push_back((fitted->second - *t.inner).norm());
  }
  Errors e;
  e.count = outer.size();
  if (outer.empty()) return e;
  auto med = [](std::vector<double> v) {
    std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
    return v[v.size() / 2];
  };
  e.outer_median = med(outer);
  e.inner_median = med(inner);
  e.outer_max = *std::max_element(outer.begin(), outer.end());
  e.inner_max = *std::max_element(inner.begin(), inner.end());
  return e;
}

// Over at least 90 % of the opening's rays, both tables within 0.3 mm (median) and 1 mm (worst)
// of the intact skull's.
void expect_near_truth(const Errors& e) {
  EXPECT_GT(e.count, the_case().defect.hole_directions.size() * 9 / 10);
  EXPECT_LT(e.outer_median, 0.3);
  EXPECT_LT(e.outer_max, 1.0);
  EXPECT_LT(e.inner_median, 0.3);
  EXPECT_LT(e.inner_max, 1.0);
}

TEST(FitDefectSurfaces, RimOnlyRecoversTheMissingBone) {
  const Case& c = the_case();
  ASSERT_TRUE(c.defect.found()) << c.defect.message;
  const DefectSurfaces s = fit_defect_surfaces(c.defect, SurfaceLocator(c.defective), nullptr);
  ASSERT_TRUE(s.fitted()) << s.message;
  EXPECT_FALSE(s.mirror_guided);
  EXPECT_GT(s.ring_rays, 200);
  const Errors e = errors_against_truth(s);
  expect_near_truth(e);
  RecordProperty("outer_median_mm", std::to_string(e.outer_median));
  RecordProperty("outer_max_mm", std::to_string(e.outer_max));
}

// The defective head with a plate seen through the opening (below).
SkullMesh with_plate_in_the_opening() {
  const Case& c = the_case();
  const Eigen::Vector3d axis = c.defect.axis;
  const Eigen::Vector3d e1 = axis.unitOrthogonal(), e2 = axis.cross(e1);
  double rim = 0.0, half = 0.0;
  for (const auto& p : c.defect.outer_rim) rim += (p - c.defect.center).norm();
  rim /= static_cast<double>(c.defect.outer_rim.size());
  for (const auto& d : c.defect.hole_directions) half = std::max(half, std::acos(d.dot(axis)));
  const double z = 0.6 * rim, w = 1.2 * z * std::tan(half);
  TriangleSoup soup = to_soup(c.defective);
  auto add_plate = [&](double from, double to, double thickness) {
    const TriangleSoup box = test::box_soup({z * std::tan(from), -w, z - 0.5 * thickness},
                                            {z * std::tan(to), w, z + 0.5 * thickness});
    const int first = static_cast<int>(soup.vertices.size());
    for (const auto& v : box.vertices)
      soup.vertices.push_back(c.defect.center + v.x() * e1 + v.y() * e2 + v.z() * axis);
    for (const auto& t : box.triangles)
      soup.triangles.push_back(t + Eigen::Vector3i::Constant(first));
  };
  add_plate(0.3 * half, 0.55 * half, 1.0);
  add_plate(0.6 * half, half, 3.0);
  return build_mesh(soup);
}

// That skull, its locator and the opening found in it, made once for the tests that use it.
struct PlateCase {
  SkullMesh skull;
  std::unique_ptr<SurfaceLocator> bone;
  DefectRegion defect;
};
const PlateCase& plate_case() {
  static const PlateCase p = [] {
    PlateCase k;
    k.skull = with_plate_in_the_opening();
    k.bone = std::make_unique<SurfaceLocator>(k.skull);
    // Its rim traced on the bone whatever the opening's size
    // (DetectDefectParams::trace_from_area_mm2).
    DetectDefectParams traced;
    traced.trace_from_area_mm2 = 0.0;
    k.defect = detect_defect(k.skull, *k.bone, the_case().defect.center, traced);
    return k;
  }();
  return p;
}

// Bone seen through the opening: next to an orbit the rays from the centre pass the vault's edge
// and meet the orbital roof, where it is thick enough to count as bone, 30-50 mm from the
// centre against the frontal bone's 80-90 mm on the sample. Here a plate 0.6 of the way out
// covers the opening's side along e1: a 1 mm strip next to the open part (its rays meet too
// little bone to be rim or ring, as the thin roof by the orbital rim) and a 3 mm part beyond
// it, whose rays cross one plausible layer of bone. That is not the vault going on: the ring
// leaves it out, and the rim-only fit does not bend down to it (on the sample from its STL the
// implant's edge had a bay 6.8 mm deep above the orbit).
TEST(FitDefectSurfaces, BoneSeenThroughTheOpeningIsNotTheVault) {
  ASSERT_TRUE(the_case().defect.found());
  const PlateCase& plate = plate_case();
  const DefectRegion& defect = plate.defect;
  ASSERT_TRUE(defect.found()) << defect.message;
  const SurfaceLocator truth(the_case().intact);
  const DefectSurfaces s = fit_defect_surfaces(defect, *plate.bone, nullptr);
  ASSERT_TRUE(s.fitted()) << s.message;
  int on_plate = 0;
  for (const auto& p : s.ring_outer) {
    const Eigen::Vector3d d = (p - defect.center).normalized();
    const RayThroughBone t = cast_through_bone(truth, defect.center, d, 400.0, 0.5, 15.0);
    on_plate += !t.paired || (p - *t.outer).norm() > 1.5;
  }
  EXPECT_EQ(on_plate, 0) << "of " << s.ring_outer.size() << " ring rays";
  std::vector<double> outer;
  for (const auto& d : defect.hole_directions) {
    const auto fitted = s.at(d);
    const RayThroughBone t = cast_through_bone(truth, defect.center, d, 400.0, 0.5, 15.0);
    if (fitted && t.paired) outer.push_back((fitted->first - *t.outer).norm());
  }
  ASSERT_GT(outer.size(), defect.hole_directions.size() / 2);
  std::sort(outer.begin(), outer.end());
  RecordProperty("outer_median_mm", std::to_string(outer[outer.size() / 2]));
  RecordProperty("outer_max_mm", std::to_string(outer.back()));
  EXPECT_LT(outer[outer.size() / 2], 0.5);
  EXPECT_LT(outer.back(), 2.0);
}

// A "healthy side" that does not match: the intact skull 4 % larger about the centre (about
// 3.5 mm too high over the opening). The correction measured on the ring takes it back.
TEST(FitDefectSurfaces, MirrorGuidedCorrectsTheMirrorsMismatch) {
  const Case& c = the_case();
  ASSERT_TRUE(c.defect.found());
  SkullMesh larger = c.intact;
  for (auto vh : larger.vertices()) larger.set_point(vh, larger.point(vh) * 1.04f);
  const SurfaceLocator prior(larger);
  // The mirror alone is far off: the correction has work to do.
  std::vector<double> raw;
  const SurfaceLocator truth(c.intact);
  for (const auto& d : c.defect.hole_directions) {
    const RayThroughBone m = cast_through_bone(prior, c.defect.center, d, 400.0, 0.5, 15.0);
    const RayThroughBone t = cast_through_bone(truth, c.defect.center, d, 400.0, 0.5, 15.0);
    if (m.paired && t.paired) raw.push_back((*m.outer - *t.outer).norm());
  }
  ASSERT_FALSE(raw.empty());
  std::nth_element(raw.begin(), raw.begin() + raw.size() / 2, raw.end());
  EXPECT_GT(raw[raw.size() / 2], 2.5);
  const DefectSurfaces s = fit_defect_surfaces(c.defect, SurfaceLocator(c.defective), &prior);
  ASSERT_TRUE(s.fitted()) << s.message;
  EXPECT_TRUE(s.mirror_guided);
  const Errors e = errors_against_truth(s);
  expect_near_truth(e);
}

// A mirror whose bone steps out by 2 mm along a line across the opening (one side of the head
// moved outward): read along one ray, the fitted outer surface steps as sharply as the mirror
// (0.59 mm over 0.1 mm), and which side of the line a marker lands on decides 2 mm of the
// implant; read over the footprint it ramps across about 6 mm, by at most 0.08 mm over 0.1 mm.
// Away from the line the footprint changes nothing.
TEST(FitDefectSurfaces, MirrorReadOverAFootprintRampsWhereItsBoneSteps) {
  const Case& c = the_case();
  ASSERT_TRUE(c.defect.found());
  const Eigen::Vector3d center = c.defect.center, axis = c.defect.axis;
  const Eigen::Vector3d across = unit_across(c.defect.frame.col(0), axis);
  SkullMesh stepped = c.intact;
  for (auto vh : stepped.vertices()) {
    const Eigen::Vector3d p = to_eigen(stepped.point(vh));
    if ((p - center).dot(across) > 0.0)
      stepped.set_point(vh, to_point(p + 2.0 * (p - center).normalized()));
  }
  const SurfaceLocator mirror(stepped), bone(c.defective);
  DefectSurfaceParams one_ray;
  one_ray.mirror_footprint_mm = 0.0;
  const DefectSurfaces along_ray = fit_defect_surfaces(c.defect, bone, &mirror, one_ray);
  const DefectSurfaces over_footprint = fit_defect_surfaces(c.defect, bone, &mirror);
  ASSERT_TRUE(along_ray.fitted()) << along_ray.message;
  ASSERT_TRUE(over_footprint.fitted()) << over_footprint.message;
  // Directions across the line, 0.1 mm apart at the outer surface, 12 mm to either side.
  auto outer_radii = [&](const DefectSurfaces& s) {
    std::vector<double> r;
    const double radius = (s.at(axis)->first - center).norm();
    for (double x = -12.0; x <= 12.0; x += 0.1) {
      const auto p = s.at((axis + x / radius * across).normalized());
      r.push_back(p ? (p->first - center).norm() : std::nan(""));
    }
    return r;
  };
  auto largest_step = [](const std::vector<double>& r) {
    double step = 0.0;
    for (size_t i = 1; i < r.size(); ++i) step = std::max(step, std::abs(r[i] - r[i - 1]));
    return step;
  };
  const std::vector<double> a = outer_radii(along_ray), b = outer_radii(over_footprint);
  for (size_t i = 0; i < a.size(); ++i) {
    ASSERT_FALSE(std::isnan(a[i]) || std::isnan(b[i])) << "the fit reaches every direction";
  }
  std::printf("largest change over 0.1 mm: %.3f mm along one ray, %.3f over the footprint\n",
              largest_step(a), largest_step(b));
  EXPECT_GT(largest_step(a), 0.4);
  EXPECT_LT(largest_step(b), 0.2);
  // A footprint that is not a number (a session edited by hand) reads along the one ray.
  DefectSurfaceParams not_a_number;
  not_a_number.mirror_footprint_mm = std::nan("");
  EXPECT_EQ(outer_radii(fit_defect_surfaces(c.defect, bone, &mirror, not_a_number)), a);
  // 6 mm and more from the line, the two agree.
  for (size_t i : {size_t{0}, size_t{60}, a.size() - 61, a.size() - 1})
    EXPECT_NEAR(a[i], b[i], 0.2) << "at " << (static_cast<double>(i) * 0.1 - 12.0) << " mm";
}

// A mirror with a hole over the opening (a foramen, a gap where the scan or the export lost
// bone). Over the footprint the ray and six around it, 3 mm off, are read, and a value needs at
// least four of the seven through both tables: a hole of 1.5 mm under the ray is read across
// from the six around it (along one ray: no value), and in a hole of 8 mm there is none at its
// middle (no ray through bone) nor 1 mm inside its edge (three of seven at most), but there is
// 2 mm outside it (four or more).
TEST(FitDefectSurfaces, MirrorFootprintReadsAcrossSmallHolesNotLargeOnes) {
  const Case& c = the_case();
  ASSERT_TRUE(c.defect.found());
  const Eigen::Vector3d center = c.defect.center, d0 = c.defect.axis;
  const Eigen::Vector3d across = unit_across(c.defect.frame.col(0), d0);
  // Millimetres across at the rim's radius, as the footprint measures them.
  double rim_radius = 0.0;
  for (const auto& p : c.defect.outer_rim) rim_radius += (p - center).norm();
  rim_radius /= static_cast<double>(c.defect.outer_rim.size());
  auto off_axis = [&](double mm) { return (d0 + mm / rim_radius * across).normalized(); };
  // Every face with a corner within `radius_mm` of the axis goes, through both tables.
  auto holed = [&](double radius_mm) {
    SkullMesh m = c.intact;
    std::vector<SkullMesh::FaceHandle> gone;
    for (auto fh : m.faces())
      for (auto vh : m.fv_range(fh)) {
        const Eigen::Vector3d v = (to_eigen(m.point(vh)) - center).normalized();
        if (v.dot(d0) > 0.0 && (v - v.dot(d0) * d0).norm() / v.dot(d0) * rim_radius < radius_mm) {
          gone.push_back(fh);
          break;
        }
      }
    for (auto fh : gone) m.delete_face(fh, true);
    m.garbage_collection();
    return m;
  };
  const SurfaceLocator bone(c.defective), whole(c.intact);
  const SkullMesh small_hole = holed(1.5), large_hole = holed(8.0);
  const SurfaceLocator small_mirror(small_hole), large_mirror(large_hole);
  // The holes are there: no ray along the axis meets both tables.
  EXPECT_FALSE(cast_through_bone(small_mirror, center, d0, 400.0, 0.5, 15.0).paired);
  EXPECT_FALSE(cast_through_bone(large_mirror, center, off_axis(7.0), 400.0, 0.5, 15.0).paired);

  const DefectSurfaces intact = fit_defect_surfaces(c.defect, bone, &whole);
  const DefectSurfaces small = fit_defect_surfaces(c.defect, bone, &small_mirror);
  ASSERT_TRUE(intact.fitted()) << intact.message;
  ASSERT_TRUE(small.fitted()) << small.message;
  const auto expected = intact.at(d0), read_across = small.at(d0);
  ASSERT_TRUE(expected.has_value());
  ASSERT_TRUE(read_across.has_value()) << "six of seven rays meet bone around a 1.5 mm hole";
  EXPECT_NEAR((read_across->first - center).norm(), (expected->first - center).norm(), 0.1);
  EXPECT_NEAR((read_across->second - center).norm(), (expected->second - center).norm(), 0.1);
  DefectSurfaceParams one_ray;
  one_ray.mirror_footprint_mm = 0.0;
  const DefectSurfaces small_one_ray = fit_defect_surfaces(c.defect, bone, &small_mirror, one_ray);
  ASSERT_TRUE(small_one_ray.fitted()) << small_one_ray.message;
  EXPECT_FALSE(small_one_ray.at(d0).has_value()) << "along one ray the hole has no bone";

  const DefectSurfaces large = fit_defect_surfaces(c.defect, bone, &large_mirror);
  ASSERT_TRUE(large.fitted()) << large.message;
  EXPECT_FALSE(large.at(d0).has_value()) << "no ray of the footprint meets bone";
  EXPECT_FALSE(large.at(off_axis(7.0)).has_value()) << "at most three of seven meet bone";
  EXPECT_FALSE(large.at(off_axis(-7.0)).has_value()) << "at most three of seven meet bone";
  for (double mm : {10.0, -10.0}) {
    const auto beyond = large.at(off_axis(mm)), there = intact.at(off_axis(mm));
    ASSERT_TRUE(beyond.has_value()) << "four or more of seven meet bone " << mm << " mm off";
    ASSERT_TRUE(there.has_value());
    // The rays that meet bone are averaged: a fraction of a millimetre from the whole read.
    EXPECT_NEAR((beyond->first - center).norm(), (there->first - center).norm(), 0.3) << mm;
  }
}

// Mirror-guided, the whole ring is fitted (the mirror meets the same roof past an orbit on the
// other side), but where it does not, a ray's mismatch is 30-50 mm. Such rays are left out of
// the fit and counted apart from its residual: on the sample a few of them made the residual
// read 3.04 mm where the rest of the ring fitted to 0.22 mm. Here the plate of the test above
// lies in the ring, and the mirror (the intact head) has no plate.
TEST(FitDefectSurfaces, RingRaysTheFitLeavesOutAreCountedApartFromItsResidual) {
  const Case& c = the_case();
  ASSERT_TRUE(c.defect.found());
  const PlateCase& plate = plate_case();
  // The opening as the rays see it (its rim not traced on the bone): the rays onto the plate
  // are then bone next to the opening, and the ring holds them.
  DetectDefectParams rays_only;
  rays_only.trace_rim_on_bone = false;
  const DefectRegion seen =
      detect_defect(plate.skull, *plate.bone, the_case().defect.center, rays_only);
  ASSERT_TRUE(seen.found()) << seen.message;
  const SurfaceLocator mirror(c.intact);
  const DefectSurfaces s = fit_defect_surfaces(seen, *plate.bone, &mirror);
  ASSERT_TRUE(s.fitted()) << s.message;
  EXPECT_GT(s.outer_off_rays, 10) << s.message;
  EXPECT_LT(s.outer_rms_mm, 0.3) << s.message;
  EXPECT_NE(s.message.find("rays left out"), std::string::npos) << s.message;
  RecordProperty("outer_off_rays", s.outer_off_rays);
  RecordProperty("outer_rms_mm", std::to_string(s.outer_rms_mm));
  // Without the plate every ray fits: none is left out.
  const DefectSurfaces clean = fit_defect_surfaces(c.defect, SurfaceLocator(c.defective), &mirror);
  ASSERT_TRUE(clean.fitted()) << clean.message;
  EXPECT_EQ(clean.outer_off_rays, 0) << clean.message;
  EXPECT_EQ(clean.message.find("rays left out"), std::string::npos) << clean.message;
  // Traced on the bone, the rim runs along the vault's edge, not the plate's: the plate's rays
  // are the opening's, and the ring has none of them.
  ASSERT_TRUE(plate.defect.rim_traced) << plate.defect.message;
  const DefectSurfaces traced = fit_defect_surfaces(plate.defect, *plate.bone, &mirror);
  ASSERT_TRUE(traced.fitted()) << traced.message;
  EXPECT_EQ(traced.outer_off_rays, 0) << traced.message;
}

// A SkullFix-like cut: an axis-aligned 60 mm cube over the upper right of a head with bone about
// 8 mm thick (as SkullFix's occiput), whose faces meet the vault at about 45°. Rays near the
// opening then enter or leave the bone through a cut face instead of a table and see it too
// thin, and the spline carries that inwards (measured: the fitted bone 0.7 mm too thin at the
// median); rays whose entry and exit surfaces are not parallel are left out of the thickness
// (0.1 mm), and rays that leave through a surface tilted far from them out of both fits (the
// outer surface: −0.11 → 0.03 mm).
TEST(FitDefectSurfaces, ObliqueCutFacesDoNotThinTheFittedBone) {
  const SkullMesh intact = test::make_thick_head(0.89);
  InjectDefectParams p;
  p.shape = InjectDefectParams::Shape::Cube;
  p.center = test::head_surface_point(Eigen::Vector3d(0.7, 0.1, 0.7).normalized());
  p.size_mm = 60;
  p.voxel_mm = 0.5;
  const SkullMesh defective = inject_defect(intact, p).defective;
  const SurfaceLocator bone(defective), truth(intact);
  const DefectRegion defect = detect_defect(defective, bone, Eigen::Vector3d::Zero());
  ASSERT_TRUE(defect.found()) << defect.message;
  // Median errors of the fitted thickness and outer radius over the opening, mm (fitted − true).
  auto median_errors = [&](double max_table_angle_deg, double max_outer_tilt_deg) {
    DefectSurfaceParams params;
    params.max_table_angle_deg = max_table_angle_deg;
    params.max_outer_tilt_deg = max_outer_tilt_deg;
    const DefectSurfaces s = fit_defect_surfaces(defect, bone, nullptr, params);
    EXPECT_TRUE(s.fitted()) << s.message;
    std::vector<double> thick, outer;
    for (const auto& d : defect.hole_directions) {
      const auto f = s.at(d);
      const RayThroughBone t = cast_through_bone(truth, defect.center, d, 400.0, 0.5, 15.0);
      if (!f || !t.paired) continue;
      thick.push_back((f->first - f->second).norm() - (*t.outer - *t.inner).norm());
      outer.push_back((f->first - defect.center).norm() - (*t.outer - defect.center).norm());
    }
    EXPECT_GT(thick.size(), defect.hole_directions.size() / 2);
    auto med = [](std::vector<double> v) {
      if (v.empty()) return 0.0;
      std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
      return v[v.size() / 2];
    };
    return std::make_pair(med(thick), med(outer));
  };
  const auto [thick, outer] = median_errors(30.0, 50.0);
  const auto [thick_unfiltered, outer_unfiltered] = median_errors(0.0, 0.0);
  RecordProperty("median_thickness_error_mm", std::to_string(thick));
  RecordProperty("median_thickness_error_unfiltered_mm", std::to_string(thick_unfiltered));
  RecordProperty("median_outer_error_mm", std::to_string(outer));
  RecordProperty("median_outer_error_unfiltered_mm", std::to_string(outer_unfiltered));
  EXPECT_LT(std::abs(thick), 0.3);
  EXPECT_LT(std::abs(outer), 0.3);
  EXPECT_LT(thick_unfiltered, thick - 0.2) << "cut-face rays thin the bone when not left out";
}

// The vault's model is chosen by how well it predicts the ring's band next to the opening from
// the rest of the ring. Two cube cuts of the synthetic head, whose truth is the intact head: a
// 100 mm cut over the round top (a quadratic trend alone sags there: the sphere is right) and a
// 60 mm cut on the flattened back (a sphere bulges there: the quadratic trend is right). In
// each the chosen model is compared with the other one, forced (median error of the outer
// surface over the opening).
TEST(FitDefectSurfaces, VaultModelIsChosenByTheRingsBandNextToTheOpening) {
  const SkullMesh intact = test::make_thick_head(0.89);
  const SurfaceLocator truth(intact);
  auto median_outer_error = [&](const DefectRegion& defect, const DefectSurfaces& s) {
    std::vector<double> e;
    for (const auto& d : defect.hole_directions) {
      const auto f = s.at(d);
      const RayThroughBone t = cast_through_bone(truth, defect.center, d, 400.0, 0.5, 15.0);
      if (f && t.paired)
        e.push_back(
            std::abs((f->first - defect.center).norm() - (*t.outer - defect.center).norm()));
    }
    EXPECT_GT(e.size(), defect.hole_directions.size() / 2);
    if (e.empty()) return 1e9;
    std::nth_element(e.begin(), e.begin() + e.size() / 2, e.end());
    return e[e.size() / 2];
  };
  struct Cut {
    Eigen::Vector3d direction;
    double size_mm;
    bool sphere_expected;
    const char* name;
  };
  for (const Cut& cut : {Cut{{0.15, -0.6, 0.8}, 100, true, "top_100mm"},
                         Cut{{0.1, -0.95, 0.15}, 60, false, "back_60mm"}}) {
    InjectDefectParams p;
    p.shape = InjectDefectParams::Shape::Cube;
    p.center = test::head_surface_point(cut.direction.normalized());
    p.size_mm = cut.size_mm;
    p.voxel_mm = 0.5;
    const SkullMesh defective = inject_defect(intact, p).defective;
    const SurfaceLocator bone(defective);
    // The choice is made on the ring the rays' opening leaves (its rim not traced on the bone:
    // traced, the rim at the cube's outer corners seeds more of the band next to it, and on the
    // top the two models' band errors come within 0.01 mm of each other; the traced rim's plans
    // are measured on SkullFix's cubes, docs/AUTOPLAN.md).
    DetectDefectParams rays_only;
    rays_only.trace_rim_on_bone = false;
    const DefectRegion defect = detect_defect(defective, bone, Eigen::Vector3d::Zero(), rays_only);
    ASSERT_TRUE(defect.found()) << cut.name << ": " << defect.message;
    auto fit = [&](DefectSurfaceParams::Vault vault) {
      DefectSurfaceParams params;
      params.vault = vault;
      const DefectSurfaces s = fit_defect_surfaces(defect, bone, nullptr, params);
      EXPECT_TRUE(s.fitted()) << cut.name << ": " << s.message;
      return s;
    };
    const DefectSurfaces chosen = fit(DefectSurfaceParams::Vault::Best);
    EXPECT_EQ(chosen.vault().has_value(), cut.sphere_expected)
        << cut.name << ": " << chosen.message;
    const double e_chosen = median_outer_error(defect, chosen);
    const double e_other =
        median_outer_error(defect, fit(cut.sphere_expected ? DefectSurfaceParams::Vault::Quadratic
                                                           : DefectSurfaceParams::Vault::Sphere));
    RecordProperty(std::string(cut.name) + "_chosen_mm", std::to_string(e_chosen));
    RecordProperty(std::string(cut.name) + "_other_mm", std::to_string(e_other));
    // Measured: top 0.23 mm against 0.50 with the quadratic trend; back 0.26 against 0.32
    // with the sphere.
    EXPECT_LT(e_chosen, e_other) << cut.name;
    EXPECT_LT(e_chosen, 0.35) << cut.name;
  }
}

// Mirror-guided, a fitting site that averages few of the ring's rays is smoothed more. The
// thick head's defect with a rough outer table (bumps of 0.4 mm, 6 mm apart) and the intact
// head as the mirror: the correction should be nothing, and the ring's roughness is what it
// must not follow. Sites of a ray or two (where the ring is cut short) catch single bumps, and
// which rays fall in them changes with where the rays start. Planned from the origin and from
// 1 mm away along each axis, the fitted outer table lies as near the truth or nearer on every
// start, and its worst error over them is smaller (measured: median 0.082 against 0.089 mm on
// average, worst 0.33 against 0.36 mm).
TEST(FitDefectSurfaces, MirrorGuidedSitesOfFewRaysBendTheCorrectionLess) {
  const Case& c = the_case();
  SkullMesh rough = c.defective;
  const double k = 2.0 * M_PI / 6.0;
  for (auto vh : rough.vertices()) {
    const Eigen::Vector3d p = to_eigen(rough.point(vh));
    const double bump =
        0.4 * std::sin(k * p.x()) * std::sin(k * p.y() + 1.0) * std::sin(k * p.z() + 2.0);
    rough.set_point(vh, to_point(p + bump * p.normalized()));
  }
  const SurfaceLocator bone(rough), truth(c.intact);
  struct Spread {
    double mean_median = 0, worst = 0;
    std::vector<double> medians;
  };
  auto over_starts = [&](bool weigh) {
    DefectSurfaceParams params;
    params.weigh_sites_by_rays = weigh;
    Spread out;
    for (int m = 0; m < 7; ++m) {
      Eigen::Vector3d start = Eigen::Vector3d::Zero();
      if (m > 0) start = (m % 2 ? 1.0 : -1.0) * Eigen::Vector3d::Unit((m - 1) / 2);
      const DefectRegion d = detect_defect(rough, bone, start);
      const DefectSurfaces s = fit_defect_surfaces(d, bone, &truth, params);
      EXPECT_TRUE(s.fitted() && s.mirror_guided) << s.message;
      std::vector<double> err;
      for (const auto& dir : c.defect.hole_directions)
        if (const auto f = s.at(dir))
          err.push_back((truth.closest(f->first).point - f->first).norm());
      if (err.empty()) continue;
      std::sort(err.begin(), err.end());
      out.medians.push_back(err[err.size() / 2]);
      out.mean_median += err[err.size() / 2] / 7.0;
      out.worst = std::max(out.worst, err.back());
    }
    return out;
  };
  const Spread alike = over_starts(false), weighed = over_starts(true);
  ASSERT_EQ(alike.medians.size(), 7u);
  ASSERT_EQ(weighed.medians.size(), 7u);
  for (size_t m = 0; m < 7; ++m) EXPECT_LE(weighed.medians[m], alike.medians[m] + 0.002) << m;
  EXPECT_LT(weighed.mean_median, alike.mean_median - 0.004);
  EXPECT_LT(weighed.worst, alike.worst - 0.015);
  EXPECT_LT(weighed.mean_median, 0.15);
  EXPECT_LT(weighed.worst, 0.5);
}

// Two fits averaged (a shape model's into the mirror's or the ring's): where the second has no
// surface over part of the opening (a model's template stopping short), its weight fades over
// the taper's width instead of stopping with a step of half their difference. Known answer: a
// prior bulging 3 mm over the opening, with a hole in it there, averaged into the truth's fit
// (measured: 0.66 mm between neighbouring rays untapered, 0.15 mm tapered).
TEST(FitDefectSurfaces, ABlendFadesOutWhereTheOtherFitHasNoSurface) {
  const Case& c = the_case();
  ASSERT_TRUE(c.defect.found());
  const Eigen::Vector3d top = test::head_surface_point(c.defect.axis);
  SkullMesh bulging = c.intact;
  for (auto vh : bulging.vertices()) {
    const Eigen::Vector3d p(bulging.point(vh)[0], bulging.point(vh)[1], bulging.point(vh)[2]);
    const double d = (p - top).norm(), w = std::max(0.0, 1.0 - std::pow(d / 45.0, 2));
    const Eigen::Vector3d q = p + 3.0 * w * w * p.normalized();
    bulging.set_point(vh, SkullMesh::Point(q.x(), q.y(), q.z()));
  }
  const Eigen::Vector3d side = c.defect.axis.cross(Eigen::Vector3d::UnitZ()).normalized();
  const SkullMesh holed = test::cut_hole(bulging, top + 10.0 * side, 9.0);
  const SurfaceLocator bone(c.defective), truth(c.intact), prior(holed);
  auto other = std::make_shared<DefectSurfaces>(fit_defect_surfaces(c.defect, bone, &prior));
  ASSERT_TRUE(other->fitted()) << other->message;
  const DefectSurfaces base = fit_defect_surfaces(c.defect, bone, &truth);
  ASSERT_TRUE(base.fitted()) << base.message;
  const auto& dirs = c.defect.hole_directions;
  size_t gaps = 0;
  for (const auto& d : dirs)
    if (base.at(d) && !other->at(d)) ++gaps;
  ASSERT_GT(gaps, 10u) << "the prior's hole lies in the opening";

  // The blend's departure from the first fit, ray by ray (outer radius, mm), and its largest
  // change between neighbouring rays (within 2.5 mm of each other at the surface).
  DefectSurfaces stepped = base, tapered = base;
  stepped.blend_with(other, 0.5, dirs, 0.0);
  tapered.blend_with(other, 0.5, dirs, 10.0);
  std::vector<Eigen::Vector3d> at;
  std::vector<double> step_dev, taper_dev;
  std::vector<char> gap;
  for (const auto& d : dirs) {
    const auto b = base.at(d), s0 = stepped.at(d), s1 = tapered.at(d);
    if (!b || !s0 || !s1) continue;
    const double r = (b->first - c.defect.center).norm();
    at.push_back(b->first);
    step_dev.push_back((s0->first - c.defect.center).norm() - r);
    taper_dev.push_back((s1->first - c.defect.center).norm() - r);
    gap.push_back(!other->at(d));
  }
  auto largest_change = [&](const std::vector<double>& dev) {
    double worst = 0.0;
    for (size_t i = 0; i < at.size(); ++i)
      for (size_t j = i + 1; j < at.size(); ++j)
        if ((at[i] - at[j]).norm() <= 2.5) worst = std::max(worst, std::abs(dev[i] - dev[j]));
    return worst;
  };
  const double step = largest_change(step_dev), smooth = largest_change(taper_dev);
  EXPECT_GT(step, 0.4) << "the untapered blend steps by half the bulge's uncorrected part";
  EXPECT_LT(smooth, 0.5 * step) << "step " << step;
  // Beside the hole (within 2 mm of its rays) the tapered blend departs from the first fit by
  // at most a fifth of what the untapered one does (smoothstep(0.2) = 0.10); at least the
  // taper's width away the two blends agree; the share the sources count fades the same way.
  const PointIndex holes([&] {
    std::vector<Eigen::Vector3d> h;
    for (size_t i = 0; i < at.size(); ++i)
      if (gap[i]) h.push_back(at[i]);
    return h;
  }());
  size_t far = 0, beside = 0;
  for (size_t i = 0; i < at.size(); ++i) {
    if (gap[i]) continue;
    double d2 = 0.0;
    holes.nearest(at[i], &d2);
    if (std::sqrt(d2) > 12.0) {
      EXPECT_NEAR(step_dev[i], taper_dev[i], 1e-9);
      ++far;
    } else if (std::sqrt(d2) < 2.0) {
      EXPECT_LE(std::abs(taper_dev[i]), 0.2 * std::abs(step_dev[i]) + 1e-9);
      ++beside;
    }
  }
  EXPECT_GT(far, 20u);
  EXPECT_GT(beside, 3u);
  size_t k = 0;
  for (const auto& d : dirs) {
    if (!base.at(d) || !other->at(d)) continue;
    const double share = tapered.blend_share(d), full = stepped.blend_share(d);
    EXPECT_EQ(full, 1.0);
    EXPECT_GE(share, 0.0);
    EXPECT_LE(share, 1.0);
    ++k;
  }
  EXPECT_GT(k, 20u);
}

TEST(FitDefectSurfaces, WithoutIntactBoneAroundItSaysSo) {
  const Case& c = the_case();
  DefectSurfaceParams p;
  p.rim_clearance_mm = 500.0;  // every ray is "too near" the opening
  const DefectSurfaces s = fit_defect_surfaces(c.defect, SurfaceLocator(c.defective), nullptr, p);
  EXPECT_FALSE(s.fitted());
  EXPECT_NE(s.message.find("too little intact bone"), std::string::npos) << s.message;
  EXPECT_FALSE(s.at(c.defect.axis).has_value());
}

}  // namespace
}  // namespace cranioplan
