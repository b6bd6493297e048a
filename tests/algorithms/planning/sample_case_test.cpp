// The whole foundation chain on the real sample case (Debian's invesalius-examples).
#include <gtest/gtest.h>

#include <Eigen/LU>
#include <filesystem>
#include <functional>

#include "cranioplan/algorithms/alignment/fit_sagittal_plane.h"
#include "cranioplan/algorithms/alignment/mirror_mesh.h"
#include "cranioplan/algorithms/alignment/register_icp.h"
#include "cranioplan/algorithms/geometry/surface_locator.h"
#include "cranioplan/algorithms/io/load_skull.h"
#include "cranioplan/algorithms/io/mesh_report.h"
#include "cranioplan/algorithms/io/read_volume.h"
#include "cranioplan/algorithms/io/write_mesh.h"
#include "cranioplan/algorithms/planning/autoplan.h"
#include "cranioplan/algorithms/quality/compare_implants.h"
#include "cranioplan/algorithms/quality/inject_defect.h"
#include "cranioplan/model/error.h"
#include "cranioplan/model/material.h"
#include "support/synthetic.h"
#include "support/test_files.h"

namespace cranioplan {
namespace {

TEST(SampleCase, ImportPlaneMirrorRegister) {
  const std::string path = sample_case_path();
  if (!std::filesystem::exists(path))
    GTEST_SKIP() << path << " not installed (scripts/install-deps)";
  const Volume volume = read_volume(path);
  // InVesalius stores rows flipped: the reader's index-to-world map must undo that mirror
  // (negative determinant), so the world coordinates are patient-true.
  EXPECT_LT(volume.directions.determinant(), 0.0);
  EXPECT_LT(volume.directions(1, 1), 0.0);
  const LoadedSkull skull = load_skull(path);
  const MeshReport rep = report_mesh(skull.mesh);
  EXPECT_GT(rep.triangles, 300000);
  EXPECT_EQ(rep.pieces, 1);
  EXPECT_EQ(rep.boundary_edges, 0);  // closed by the padding, even where bone meets the scan edge
  EXPECT_GT(rep.volume_mm3, 0);
  // A head: 12–25 cm across in every direction.
  const Eigen::Vector3d size = rep.bbox_max - rep.bbox_min;
  EXPECT_GT(size.minCoeff(), 120.0);
  EXPECT_LT(size.maxCoeff(), 250.0);

  const PlaneFit fit = fit_sagittal_plane(skull.mesh, Landmarks{});
  ASSERT_TRUE(fit.usable()) << fit.message;
  // The scan is roughly aligned: the left-right axis is the image x axis.
  EXPECT_GT(std::abs(fit.plane.normal.x()), 0.98);
  EXPECT_LT(fit.symmetry_rms_mm, 1.2);
  EXPECT_GT(fit.inlier_fraction, 0.6);
  // The plane passes through the middle of the head.
  const double mid = 0.5 * (rep.bbox_min.x() + rep.bbox_max.x());
  EXPECT_LT(std::abs(fit.plane.offset / fit.plane.normal.x() - mid), 15.0);

  const SkullMesh mirrored = mirror_mesh(skull.mesh, fit.plane);
  EXPECT_GT(signed_volume(mirrored), 0);
  const RegisterResult reg = register_icp(mirrored, skull.mesh);
  ASSERT_TRUE(reg.usable()) << reg.message;
  // The plane was already good: registration only corrects a little.
  EXPECT_LT(reg.transform.rotation_angle_deg(), 2.0);
  EXPECT_LT(reg.transform.translation.norm(), 3.0);
  EXPECT_LT(reg.rms_mm, 1.2);
}

// The sample's real right frontal defect, planned automatically and built as a shell.
TEST(SampleCase, AutoplanFillsTheRealDefect) {
  const std::string path = sample_case_path();
  if (!std::filesystem::exists(path))
    GTEST_SKIP() << path << " not installed (scripts/install-deps)";
  const LoadedSkull skull = load_skull(path);
  const AutoplanResult r = autoplan(skull.mesh, Landmarks{});
  ASSERT_TRUE(r.planned()) << r.message;
  EXPECT_EQ(r.method_used, PlanMethod::Mirror);
  EXPECT_TRUE(test::on_the_patients_right_in_front(r.plane.plane, r.defect));
  // The target on the sample's real defect, from autoplan alone: a watertight shell
  // with a rim gap of at most 0.5 mm and no penetration into the skull (the shell is fitted to
  // the bone: built 4 mm over it and trimmed by it), and printable by the quality report (its
  // edge on the bone tapers over 1.5 mm; docs/IMPLANT.md). Measured 0.09 mm over the worst 5°
  // arc of the rim (the STL of scripts/run-sample is read as this very mesh).
  EXPECT_TRUE(r.quality.watertight);
  EXPECT_TRUE(r.quality.manifold);
  EXPECT_EQ(r.quality.self_intersections, 0);
  EXPECT_LE(r.quality.rim_gap_mm, 0.5);
  EXPECT_TRUE(r.quality.printable) << (r.quality.reasons.empty() ? "" : r.quality.reasons[0]);
  // "None" at the resolution of the measurement: the overlap is counted in 0.25 mm voxels and a
  // flush contact is placed within half a voxel (TrimToBone tests), so 0.25 mm³ (16 voxels)
  // is the floor; the unfitted shell overlaps the bone by about 43 mm³.
  EXPECT_LT(r.quality.penetration_mm3, 0.25);
  // The fit to the bone's two rules (thin fills removed, a clearance to the bone), on this
  // defect: planned with fills kept as made, the implant has a rod from its edge to a fragment
  // by the orbit that the quality report rejects (a corner reaching 0.85 mm past 1 mm thick,
  // measured); with a one-voxel keep-out instead of the clearance it stands further off the
  // bone: rim gap 0.16 mm against 0.09 mm, measured with support markers on every ring point
  // of the band (the worst arc then lies on bone both rules meet; with today's support markers
  // it lies where the rim runs unseen into the orbit's roof, the same under both rules). These
  // plans start their rays from the skull's vertex centroid on the plane: from there the
  // rim's unseen stretch by the orbit is 26 mm long and the rod forms (from the program's
  // own start, nearer the opening, it is 14 mm and the fill it leaves is thin enough anyway),
  // and their rays cross at most 15 mm of bone: with the default 20 mm the rim follows the
  // frontal sinus's front wall and the fragment the rod reaches is no longer at the edge. Their
  // fitting sites are weighed alike, as before propose_markers 6: weighed by their rays, these
  // plans have no rod, and the two rules leave rim gaps within 0.01 mm of each other.
  {
    AutoplanParams kept;
    kept.propose.detect.center = r.plane.plane.project(vertex_centroid(skull.mesh));
    kept.propose.detect.max_thickness_mm = 15.0;
    kept.propose.surfaces.weigh_sites_by_rays = false;
    kept.implant.trim.thin_fills_removed = false;
    const AutoplanResult rod = autoplan(skull.mesh, Landmarks{}, kept);
    ASSERT_TRUE(rod.planned()) << rod.message;
    EXPECT_GT(rod.quality.corner_reach_mm, 0.8) << "the case has the rod the rule removes";
    EXPECT_FALSE(rod.quality.printable);
    AutoplanParams every_ring;
    every_ring.propose.detect.center = kept.propose.detect.center;
    every_ring.propose.detect.max_thickness_mm = 15.0;
    every_ring.propose.surfaces.weigh_sites_by_rays = false;
    every_ring.propose.max_support_off_fit_mm = 0.0;
    const AutoplanResult clearance = autoplan(skull.mesh, Landmarks{}, every_ring);
    ASSERT_TRUE(clearance.planned()) << clearance.message;
    AutoplanParams voxel_rule = every_ring;
    voxel_rule.implant.trim.clearance_mm.reset();
    voxel_rule.implant.trim.thin_fills_removed = false;
    const AutoplanResult off = autoplan(skull.mesh, Landmarks{}, voxel_rule);
    ASSERT_TRUE(off.planned()) << off.message;
    EXPECT_GT(off.quality.rim_gap_mm, clearance.quality.rim_gap_mm + 0.03);
  }
  RecordProperty("rim_gap_mm", std::to_string(r.quality.rim_gap_mm));
  RecordProperty("penetration_mm3", std::to_string(r.quality.penetration_mm3));
  RecordProperty("thickness_min_mm", std::to_string(r.quality.thickness_min_mm));
}

// The sample turned a quarter turn about the left-right axis and moved: its frontal defect
// then faces down, where a rule "the skull base is the opening below" would take it for the
// base and plan the foramen magnum instead. The same defect must be found and the same implant
// built (measured: DSC 0.967 between the two poses, rim gap 0.15 mm; five other poses 0.93–0.97,
// docs/AUTOPLAN.md).
TEST(SampleCase, TurnedSkullGivesTheSamePlan) {
  const std::string path = sample_case_path();
  if (!std::filesystem::exists(path))
    GTEST_SKIP() << path << " not installed (scripts/install-deps)";
  const LoadedSkull skull = load_skull(path);
  const RigidTransform pose =
      RigidTransform::from_axis_angle(Eigen::Vector3d::UnitX(), 90.0, {40.0, -250.0, 80.0});
  const AutoplanResult upright = autoplan(skull.mesh, Landmarks{});
  const AutoplanResult turned = autoplan(test::transformed(skull.mesh, pose), Landmarks{});
  ASSERT_TRUE(upright.planned()) << upright.message;
  ASSERT_TRUE(turned.planned()) << turned.message;
  EXPECT_GT(turned.defect.axis.dot(pose.rotation * upright.defect.axis), std::cos(M_PI / 36));
  EXPECT_EQ(turned.method_used, PlanMethod::Mirror);
  EXPECT_LE(turned.quality.rim_gap_mm, 0.5);
  EXPECT_LT(turned.quality.penetration_mm3, 0.25);
  const CompareResult same = compare_implants(
      test::transformed(turned.implant.mesh, pose.inverse()), upright.implant.mesh, &skull.mesh);
  RecordProperty("dice_between_poses", std::to_string(same.dice));
  EXPECT_GE(same.dice, 0.9) << "HD95 " << same.hd95_mm;
}

// The same surface from another file plans to the same implant: the CT mesh, an STL of it (the
// STL reader welds the CT mesh's 682 duplicate vertices and lists the rest in another order) and
// a PLY of it. Meshes are read in a canonical form (make_canonical), so the plane's and the
// registration's samples, taken by vertex index, are the same (read as the files give them, the
// CT mesh and its STL gave planes 0.6° apart and implants with DSC 0.82 between them).
TEST(SampleCase, TheSameSurfaceFromAnotherFileGivesTheSameImplant) {
  const std::string path = sample_case_path();
  if (!std::filesystem::exists(path))
    GTEST_SKIP() << path << " not installed (scripts/install-deps)";
  const LoadedSkull skull = load_skull(path);
  const test::TempDir dir;
  write_mesh(skull.mesh, dir.path("skull.stl"));
  write_mesh(skull.mesh, dir.path("skull.ply"));
  const AutoplanResult reference = autoplan(skull.mesh, Landmarks{});
  ASSERT_TRUE(reference.planned()) << reference.message;
  const TriangleSoup expected = to_soup(reference.implant.mesh);
  for (const char* name : {"skull.stl", "skull.ply"}) {
    const LoadedSkull copy = load_skull(dir.path(name));
    EXPECT_EQ(copy.mesh.n_vertices(), skull.mesh.n_vertices()) << name;
    const AutoplanResult r = autoplan(copy.mesh, Landmarks{});
    ASSERT_TRUE(r.planned()) << name << ": " << r.message;
    EXPECT_EQ(r.plane.plane.normal, reference.plane.plane.normal) << name;
    const TriangleSoup got = to_soup(r.implant.mesh);
    EXPECT_EQ(got.vertices, expected.vertices) << name;
    EXPECT_EQ(got.triangles, expected.triangles) << name;
  }
}

// The sample's surface damaged as exporters and repairs damage it: a slab of triangles wound
// the other way, another slab written twice (the copy wound the other way), and single
// triangles lost here and there. It reads as the sample's own mesh, vertex for vertex and
// triangle for triangle, so every later stage and the implant are the same (read as they came,
// one such damage at the defect's rim moved the implant to Dice 0.84-0.86; docs/AUTOPLAN.md).
TEST(SampleCase, ADamagedCopyOfTheSurfaceReadsAsTheSurface) {
  const std::string path = sample_case_path();
  if (!std::filesystem::exists(path))
    GTEST_SKIP() << path << " not installed (scripts/install-deps)";
  const LoadedSkull skull = load_skull(path);
  const TriangleSoup clean = to_soup(skull.mesh);
  const size_t n = clean.triangles.size();
  // Canonical order runs along x: each range is a slab across the head.
  auto in_range = [n](size_t t, double from, double width) {
    return t >= static_cast<size_t>(from * n) && t < static_cast<size_t>((from + width) * n);
  };
  TriangleSoup damaged;
  damaged.vertices = clean.vertices;
  std::vector<char> corner_lost(clean.vertices.size(), 0);
  long long flipped = 0, doubled = 0, lost = 0;
  for (size_t t = 0; t < n; ++t) {
    Eigen::Vector3i f = clean.triangles[t];
    const bool flip = in_range(t, 0.1, 0.025), twice = in_range(t, 0.5, 0.01);
    // Lost alone: no corner shared with another lost triangle (a hole of its own three edges).
    if (!flip && !twice && t % 997 == 0 && !corner_lost[f[0]] && !corner_lost[f[1]] &&
        !corner_lost[f[2]]) {
      for (int k = 0; k < 3; ++k) corner_lost[f[k]] = 1;
      ++lost;
      continue;
    }
    if (flip) {
      std::swap(f[1], f[2]);
      ++flipped;
    }
    damaged.triangles.push_back(f);
    if (twice) {
      damaged.triangles.emplace_back(f[0], f[2], f[1]);
      ++doubled;
    }
  }
  ASSERT_GT(lost, 100);
  const test::TempDir dir;
  write_mesh(skull.mesh, dir.path("clean.stl"));
  write_mesh(build_mesh(damaged), dir.path("damaged.stl"));
  const LoadedSkull read = load_skull(dir.path("damaged.stl"));
  const TriangleSoup a = to_soup(read.mesh), b = to_soup(load_skull(dir.path("clean.stl")).mesh);
  EXPECT_EQ(a.vertices, b.vertices);
  EXPECT_EQ(a.triangles, b.triangles);
  std::string said;
  for (const std::string& w : read.warnings) said += w + "\n";
  for (const std::string& repair :
       {format_count(doubled) + " triangles repeat another's three corners",
        format_count(flipped) + " triangles in ", format_count(lost) + " small holes (up to "})
    EXPECT_NE(said.find(repair), std::string::npos) << repair << " in:\n" << said;
}

// The sample decimated to 250,000 triangles (as a lighter export from another tool would be):
// a few rim points then lie on bone 20-30 mm below their neighbours on the rim (the sinus wall
// and orbital roof seen past the crushed supraorbital bone), where the mirror has no bone to
// fit either; edge markers there pulled the implant down into a funnel that the fit to the
// bone cut away (a bay with a rim gap of 4.8-7.2 mm without the rule on neighbours). The
// implant meets the bone within the printable limit (1 mm) all round,
// not within the 0.5 mm it does on the CT mesh: where the orbit's thin bone is lost to the
// decimation, its free edge over the orbit stands 0.54 mm off the last fragment along a 5° arc
// (fixed sectors, which cut across that arc, read 0.09 mm).
TEST(SampleCase, ADecimatedCopyIsPlannedAsWell) {
  const std::string path = sample_case_path();
  if (!std::filesystem::exists(path))
    GTEST_SKIP() << path << " not installed (scripts/install-deps)";
  ExtractBoneSurfaceParams import;
  import.target_triangles = 250000;
  const LoadedSkull skull = load_skull(path, import);
  ASSERT_LT(skull.mesh.n_faces(), 260000u);
  const AutoplanResult r = autoplan(skull.mesh, Landmarks{});
  ASSERT_TRUE(r.planned()) << r.message;
  EXPECT_EQ(r.method_used, PlanMethod::Mirror);
  EXPECT_LE(r.quality.rim_gap_mm, 1.0);
  EXPECT_LT(r.quality.penetration_mm3, 0.25);
  EXPECT_TRUE(r.quality.printable) << (r.quality.reasons.empty() ? "" : r.quality.reasons[0]);
  RecordProperty("rim_gap_mm", std::to_string(r.quality.rim_gap_mm));
}

// Most exporters leave the skull open where the scan ends: the sample's own import without the
// cap over its lowest slice (the faces below z = 0, where the padding closed it), as marching
// cubes gives it on the unpadded volume. Its inside must be the bone's: planned, printable, no
// overlap and the rim on the bone as on the closed import (measured: rim gap 0.09 mm, no
// overlap, Dice 0.90 against the closed import's plan; with parity along z alone the fit and
// the check took the air above the cut for bone: rim gap 1.25 mm, 2.7 mm³ overlap).
TEST(SampleCase, AnExportOpenWhereTheScanEndsIsPlannedOnTheBone) {
  const std::string path = sample_case_path();
  if (!std::filesystem::exists(path))
    GTEST_SKIP() << path << " not installed (scripts/install-deps)";
  const LoadedSkull skull = load_skull(path);
  const SkullMesh open =
      test::cut_open(skull.mesh, Eigen::Vector3d(0, 0, -1e-3), Eigen::Vector3d::UnitZ());
  const MeshReport rep = report_mesh(open);
  ASSERT_GT(rep.boundary_edges, 500) << "the export is open along the scan's lower border";

  const AutoplanResult closed_plan = autoplan(skull.mesh, Landmarks{});
  ASSERT_TRUE(closed_plan.planned()) << closed_plan.message;
  const AutoplanResult r = autoplan(open, Landmarks{});
  ASSERT_TRUE(r.planned()) << r.message;
  EXPECT_EQ(r.method_used, PlanMethod::Mirror);
  EXPECT_LE(r.quality.rim_gap_mm, 0.5);
  EXPECT_LT(r.quality.penetration_mm3, 0.25);
  EXPECT_TRUE(r.quality.printable) << (r.quality.reasons.empty() ? "" : r.quality.reasons[0]);
  const CompareResult c = compare_implants(r.implant.mesh, closed_plan.implant.mesh);
  EXPECT_GT(c.dice, 0.88);
  RecordProperty("rim_gap_mm", std::to_string(r.quality.rim_gap_mm));
  RecordProperty("dice_vs_closed", std::to_string(c.dice));
  // Given the scan's borders from the report made when the mesh was read (load_skull's, as
  // `cranioplan-cli autoplan` gives them) instead of finding them again: the same plan.
  AutoplanParams given;
  given.propose.detect.scan_borders = scan_borders(rep);
  ASSERT_FALSE(given.propose.detect.scan_borders->empty());
  const AutoplanResult same = autoplan(open, Landmarks{}, given);
  ASSERT_TRUE(same.planned()) << same.message;
  EXPECT_EQ(same.implant.mesh.n_faces(), r.implant.mesh.n_faces());
  EXPECT_DOUBLE_EQ(same.quality.volume_mm3, r.quality.volume_mm3);
  EXPECT_EQ(same.defect.area_mm2, r.defect.area_mm2);
}

// Decimated much further (60,000 triangles, edges about 3.5 mm), the thin bone around the
// foramen magnum and the orbits opens up: the foramen's mean direction came to lie 113° from the
// vault's (124° on the CT mesh): with a limit of 114° for the base the largest opening beyond
// it was an orbit, and the foramen magnum was planned as the defect. The base is the largest
// opening more than 105° from the vault: the frontal defect is found,
// mirror-guided. Its plan is not printable (the rim is unseen along 59 mm by the crushed orbit,
// and the implant stands 1.7 mm off the bone there; docs/AUTOPLAN.md) and says so.
TEST(SampleCase, ACoarseCopyStillHasItsDefectFoundNotItsBase) {
  const std::string path = sample_case_path();
  if (!std::filesystem::exists(path))
    GTEST_SKIP() << path << " not installed (scripts/install-deps)";
  ExtractBoneSurfaceParams import;
  import.target_triangles = 60000;
  const LoadedSkull skull = load_skull(path, import);
  ASSERT_LT(skull.mesh.n_faces(), 65000u);
  const AutoplanResult r = autoplan(skull.mesh, Landmarks{});
  ASSERT_TRUE(r.planned()) << r.message;
  // The frontal defect (on the CT mesh: axis (−0.39, −0.80, 0.46), 853 mm²), on the patient's
  // right and in front, not the foramen magnum (behind and below: (0.00, 0.54, −0.84)).
  EXPECT_GT(r.defect.axis.dot(Eigen::Vector3d(-0.39, -0.80, 0.46).normalized()), 0.95)
      << r.defect.axis.transpose();
  EXPECT_GT(r.defect.area_mm2, 600.0);
  EXPECT_EQ(r.method_used, PlanMethod::Mirror);
  EXPECT_GT(r.mirror_coverage, 0.9);
  EXPECT_TRUE(r.quality.watertight);
  // Where the rim gap is over the limit (on this copy it is: the crushed orbit, 1.7 mm), the
  // report says so in a reason of its own.
  bool names_the_gap = false;
  for (const std::string& why : r.quality.reasons)
    names_the_gap = names_the_gap || why.find("between the rim and the bone") != std::string::npos;
  EXPECT_EQ(names_the_gap, r.quality.rim_gap_mm > QualityParams{}.max_rim_gap_mm)
      << r.quality.rim_gap_mm;
  // The overlap with the bone is not asserted: this copy of the skull is not closed (its STL
  // has 95 boundary edges and 174 non-manifold ones), so its inside is not well defined
  // (measured 0.7 mm³).
  RecordProperty("rim_gap_mm", std::to_string(r.quality.rim_gap_mm));
  RecordProperty("penetration_mm3", std::to_string(r.quality.penetration_mm3));
  RecordProperty("area_mm2", std::to_string(r.defect.area_mm2));
}

// A large one-sided defect low on the side of the head (100 mm, as a decompressive
// craniectomy reaching down to the temporal fossa) points 109° from the vault: further from it
// than the 105° beyond which an opening may be the skull base, and larger than the foramen
// magnum, so the rule on the angle alone took it for the base and planned another opening.
// The base must also lie within 30° of the midsagittal plane; this defect lies 45° from it.
TEST(SampleCase, ALargeDefectLowOnTheSideIsNotTakenForTheBase) {
  const std::string path = sample_case_path();
  if (!std::filesystem::exists(path))
    GTEST_SKIP() << path << " not installed (scripts/install-deps)";
  const LoadedSkull skull = load_skull(path);
  const SurfaceLocator bone(skull.mesh);
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  for (auto vh : skull.mesh.vertices()) centroid += to_eigen(skull.mesh.point(vh));
  centroid /= static_cast<double>(skull.mesh.n_vertices());
  // On the patient's left (+x), in front (−y) and low (−z), in the middle of the bone.
  const Eigen::Vector3d dir = Eigen::Vector3d(1.0, -0.6, -0.6).normalized();
  const auto outside = bone.first_hit(centroid + 400.0 * dir, centroid);
  const auto inside = bone.first_hit(centroid, centroid + 400.0 * dir);
  ASSERT_TRUE(outside && inside);
  InjectDefectParams cut;
  cut.center = 0.5 * (outside->point + inside->point);
  cut.size_mm = 100.0;
  cut.voxel_mm = 0.5;
  const InjectDefectResult d = inject_defect(skull.mesh, cut);
  ASSERT_TRUE(d.usable());
  AutoplanParams params;
  params.propose.detect.near = cut.center;  // the skull's own defect is there too
  // The sample's import is capped where the scan ended, and the defect's lowest rays go on
  // within the head's outline down to that cap: taken for the scan's end, they leave the
  // opening seen 100° from the vault. Told that the scan ended nowhere (no border), every ray
  // of the defect counts and the opening is seen beyond 105°, where the angle alone would take
  // it for the base.
  AutoplanParams untold = params;
  untold.propose.detect.scan_borders = std::vector<ScanBorder>{};
  for (const AutoplanParams& p : {untold, params}) {
    const bool told = !p.propose.detect.scan_borders.has_value();
    SCOPED_TRACE(told ? "the scan's end found" : "no scan's end");
    const AutoplanResult r = autoplan(d.defective, Landmarks{}, p);
    ASSERT_TRUE(r.planned()) << r.message;
    const Eigen::Vector3d towards = (cut.center - r.defect.center).normalized();
    EXPECT_GT(r.defect.axis.dot(towards), std::cos(15.0 * M_PI / 180.0)) << r.message;
    EXPECT_GT(r.defect.area_mm2, 8000.0) << r.message;
    if (!told) {
      EXPECT_LT(r.defect.axis.dot(r.defect.up), std::cos(105.0 * M_PI / 180.0))
          << "the case reaches past the base's angle";
    }
    RecordProperty(told ? "angle_from_vault_deg" : "angle_from_vault_deg_untold",
                   std::to_string(std::acos(r.defect.axis.dot(r.defect.up)) * 180.0 / M_PI));
  }
}

// The same defect planned from the rim alone, as for a defect the mirror cannot fill: the
// implant must still meet the real bone all round and be printable. Next to a real defect's rim
// the bone thins and bends, and the support markers there carry that to the implant (only rays
// through both tables for them open the rim gap to 4 mm). The orbital roof seen past the rim
// must not be taken for the vault (BoneSeenThroughTheOpeningIsNotTheVault): that made a bay
// 6.8 mm deep above the orbit. The STL is read as this very mesh
// (TheSameSurfaceFromAnotherFileGivesTheSameImplant). Over 14 readings and poses of the sample
// every rim-only plan is printable (docs/AUTOPLAN.md).
TEST(SampleCase, RimOnlyPlanMeetsTheRealBone) {
  const std::string path = sample_case_path();
  if (!std::filesystem::exists(path))
    GTEST_SKIP() << path << " not installed (scripts/install-deps)";
  const LoadedSkull skull = load_skull(path);
  AutoplanParams params;
  params.propose.method = PlanMethod::RimOnly;
  const AutoplanResult r = autoplan(skull.mesh, Landmarks{}, params);
  ASSERT_TRUE(r.planned()) << r.message;
  EXPECT_EQ(r.method_used, PlanMethod::RimOnly);
  EXPECT_TRUE(r.quality.watertight);
  EXPECT_LE(r.quality.rim_gap_mm, 0.5);
  EXPECT_LT(r.quality.penetration_mm3, 0.25);
  EXPECT_TRUE(r.quality.printable) << (r.quality.reasons.empty() ? "" : r.quality.reasons[0]);
  RecordProperty("rim_gap_mm", std::to_string(r.quality.rim_gap_mm));
}

// The sample's PEEK plan, its rays crossing up to 20 mm of bone (the default, set here so that
// the case stays the same: the rim then follows the frontal sinus's front wall;
// docs/AUTOPLAN.md), every fitting site weighed alike (as propose_markers 5 fitted them; the
// plan weighed by its sites' rays has neither the tab nor the hole these tests need) and inner
// support markers however thick the ring (as propose_markers 6 placed them), made with
// today's rules and as build_implant 11 made it: `set(params, today)` adds the tabs or holes
// and chooses the rule. Empty when the sample is not installed.
std::vector<AutoplanResult> peek_plans_over_the_sinus(
    const std::function<void(ImplantParams&, bool)>& set) {
  const std::string path = sample_case_path();
  if (!std::filesystem::exists(path)) return {};
  const LoadedSkull skull = load_skull(path);
  std::vector<AutoplanResult> plans;
  for (const bool today : {true, false}) {
    AutoplanParams params;
    params.propose.detect.max_thickness_mm = 20.0;
    params.propose.surfaces.weigh_sites_by_rays = false;
    params.propose.max_support_layers = 0.0;  // as propose_markers 6 placed them
    params.implant.material = material_preset("peek");
    set(params.implant, today);
    plans.push_back(autoplan(skull.mesh, Landmarks{}, params));
  }
  return plans;
}

// On that plan the even placement puts one tab on the fragments over the sinus, where it would
// stand 0.28 mm off their uneven surface (the quality report allows 0.2 mm). Placed again away
// from there, every tab rests on the bone and the plan is printable; placed once, as
// build_implant 11 placed them, it is refused for that tab.
TEST(SampleCase, ATabThatWouldStandOffTheBoneIsPlacedAgain) {
  const std::vector<AutoplanResult> plans =
      peek_plans_over_the_sinus([](ImplantParams& p, bool today) {
        p.tabs.automatic = true;
        p.tabs.keep_on_bone = today;
      });
  if (plans.empty()) GTEST_SKIP() << sample_case_path() << " not installed";
  for (const bool today : {true, false}) {
    SCOPED_TRACE(today ? "placed again" : "placed once");
    const AutoplanResult& r = plans[today ? 0 : 1];
    ASSERT_TRUE(r.planned()) << r.message;
    ASSERT_EQ(r.implant.tabs.size(), 4u) << r.implant.message;
    const bool moved = r.implant.message.find("1 tab moved along the rim") != std::string::npos;
    EXPECT_EQ(moved, today) << r.implant.message;
    EXPECT_EQ(r.quality.printable, today)
        << (r.quality.reasons.empty() ? "" : r.quality.reasons[0]);
    if (today) {
      EXPECT_LE(std::abs(r.quality.tab_gap_mm), 0.2);
      RecordProperty("tab_gap_mm", std::to_string(r.quality.tab_gap_mm));
    } else {
      EXPECT_GT(r.quality.tab_gap_mm, 0.2);
    }
  }
}

// On that plan, where the implant turns down over the sinus, one of the pattern's holes would
// leave a rim thinner than PEEK's 2 mm reaching 0.89 mm out of the thick material (the quality
// report allows 0.8 mm). That hole is left out and the plan is printable; drilled as
// build_implant 11 drilled every pattern hole, it is refused.
TEST(SampleCase, APatternHoleThatWouldLeaveAThinCornerIsLeftOut) {
  const std::vector<AutoplanResult> plans =
      peek_plans_over_the_sinus([](ImplantParams& p, bool today) {
        p.perforations.pattern = true;
        p.perforations.sound_rims = today;
      });
  if (plans.empty()) GTEST_SKIP() << sample_case_path() << " not installed";
  for (const bool today : {true, false}) {
    SCOPED_TRACE(today ? "sound rims" : "every hole drilled");
    const AutoplanResult& r = plans[today ? 0 : 1];
    ASSERT_TRUE(r.planned()) << r.message;
    ASSERT_FALSE(r.implant.holes.empty()) << r.implant.message;
    const bool left_out = r.implant.message.find("of the pattern's left out") != std::string::npos;
    EXPECT_EQ(left_out, today) << r.implant.message;
    EXPECT_EQ(r.quality.printable, today)
        << r.quality.corner_reach_mm
        << " mm: " << (r.quality.reasons.empty() ? "" : r.quality.reasons[0]);
    EXPECT_EQ(r.quality.corner_reach_mm <= 0.8, today) << r.quality.corner_reach_mm;
    RecordProperty(today ? "corner_sound_mm" : "corner_every_hole_mm",
                   std::to_string(r.quality.corner_reach_mm));
  }
}

}  // namespace
}  // namespace cranioplan
