#include "cranioplan/algorithms/planning/autoplan.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <filesystem>

#include "cranioplan/algorithms/alignment/fit_sagittal_plane.h"
#include "cranioplan/algorithms/alignment/mirror_mesh.h"
#include "cranioplan/algorithms/geometry/surface_locator.h"
#include "cranioplan/algorithms/geometry/voxelize_mesh.h"
#include "cranioplan/algorithms/io/extract_bone_surface.h"
#include "cranioplan/algorithms/io/load_skull.h"
#include "cranioplan/algorithms/io/read_volume.h"
#include "cranioplan/algorithms/quality/compare_implants.h"
#include "cranioplan/algorithms/quality/flap_defect.h"
#include "cranioplan/algorithms/quality/inject_defect.h"
#include "support/synthetic.h"

namespace cranioplan {
namespace {

const SkullMesh& thick_head() {
  static const SkullMesh head = test::make_thick_head();
  return head;
}

// A spherical defect of `size` mm centred in the bone in `direction` from the head's centre.
InjectDefectParams defect_params(const Eigen::Vector3d& direction, double size) {
  InjectDefectParams p;
  p.center = test::head_surface_point(direction.normalized()) * 0.965;
  p.size_mm = size;
  p.voxel_mm = 0.5;
  return p;
}

InjectDefectResult defect_at(const Eigen::Vector3d& direction, double size) {
  return inject_defect(thick_head(), defect_params(direction, size));
}

// The target: DSC >= 0.9 (and HD95 <= 1.5 mm, the target on real skulls).
TEST(Autoplan, OneSidedDefectInASymmetricSkullIsFilled) {
  const InjectDefectResult d = defect_at({0.75, 0.2, 0.6}, 45);
  ASSERT_TRUE(d.usable());
  const AutoplanResult r = autoplan(d.defective, Landmarks{});
  ASSERT_TRUE(r.planned()) << r.message;
  EXPECT_EQ(r.method_used, PlanMethod::Mirror);
  const CompareResult c = compare_implants(r.implant.mesh, d.implant, &d.defective);
  RecordProperty("dice", std::to_string(c.dice));
  RecordProperty("hd95_mm", std::to_string(c.hd95_mm));
  EXPECT_GE(c.dice, 0.9) << "HD95 " << c.hd95_mm;
  EXPECT_LE(c.hd95_mm, 1.5);
  EXPECT_TRUE(r.quality.watertight);
}

// Across the midline the mirror cannot help: rim-only fitting bridges the opening (the issue's
// target, DSC >= 0.85; measured 0.96).
TEST(Autoplan, DefectAcrossTheMidlineIsBridgedByRimFitting) {
  const InjectDefectResult d = defect_at({0.0, -0.3, 1.0}, 50);
  ASSERT_TRUE(d.usable());
  const AutoplanResult r = autoplan(d.defective, Landmarks{});
  ASSERT_TRUE(r.planned()) << r.message;
  EXPECT_EQ(r.method_used, PlanMethod::RimOnly);
  EXPECT_LT(r.mirror_coverage, 0.2);
  EXPECT_TRUE(r.quality.watertight);
  const CompareResult c = compare_implants(r.implant.mesh, d.implant, &d.defective);
  RecordProperty("dice", std::to_string(c.dice));
  EXPECT_GE(c.dice, 0.85) << "HD95 " << c.hd95_mm;
  EXPECT_EQ(r.quality.self_intersections, 0);
}

// A SkullFix-like cut across the midline: a 60 mm cube whose faces meet the vault obliquely.
// Next to such a face the rays from inside meet the bone's inner corner while the outer table
// goes on a few millimetres further out: the outer edge markers belong on the outer table (the
// fitted outer surface), else the implant tapers down to the corner and leaves the wedge
// between the cut face and the rays empty (markers at the last bone the rays meet put 3 of
// 33 here, and whole sides of SkullFix's cubes, at the inner corner, 7.4 mm below the outer
// table).
struct ObliqueCut {
  SkullMesh intact = test::make_thick_head(0.89);
  InjectDefectResult defect;
  AutoplanResult plan;
};
const ObliqueCut& oblique_cut() {
  static const ObliqueCut cut = [] {
    ObliqueCut c;
    InjectDefectParams p;
    p.shape = InjectDefectParams::Shape::Cube;
    p.center = test::head_surface_point(Eigen::Vector3d(0.15, -0.6, 0.8).normalized());
    p.size_mm = 60;
    p.voxel_mm = 0.5;
    c.defect = inject_defect(c.intact, p);
    if (c.defect.usable()) c.plan = autoplan(c.defect.defective, Landmarks{});
    return c;
  }();
  return cut;
}

// The intact skull's tables along the ray from the plan's detection centre through a marker.
RayThroughBone tables_along(const SurfaceLocator& truth, const AutoplanResult& r, const Marker& m) {
  const Eigen::Vector3d ray = (m.position - r.defect.center).normalized();
  return cast_through_bone(truth, r.defect.center, ray, 400.0, 0.5, 15.0);
}

TEST(Autoplan, OuterEdgeMarkersAtAnObliqueCutStayOnTheOuterTable) {
  const SkullMesh& intact = oblique_cut().intact;
  const InjectDefectResult& d = oblique_cut().defect;
  ASSERT_TRUE(d.usable());
  const AutoplanResult& r = oblique_cut().plan;
  ASSERT_TRUE(r.planned()) << r.message;
  EXPECT_EQ(r.method_used, PlanMethod::RimOnly);
  const SurfaceLocator truth(intact);
  int edges = 0;
  for (const auto& m : r.markers) {
    if (m.type != MarkerType::OuterEdge) continue;
    ++edges;
    const RayThroughBone t = tables_along(truth, r, m);
    ASSERT_TRUE(t.paired) << "edge marker " << m.id;
    EXPECT_NEAR((m.position - r.defect.center).norm(), (*t.outer - r.defect.center).norm(), 1.0)
        << "edge marker " << m.id << " is not on the outer table";
  }
  EXPECT_GE(edges, 20);
  const CompareResult c = compare_implants(r.implant.mesh, d.implant, &d.defective);
  RecordProperty("dice", std::to_string(c.dice));
  RecordProperty("boundary_dice", std::to_string(c.boundary_dice));
  EXPECT_GE(c.dice, 0.92) << "HD95 " << c.hd95_mm;
  EXPECT_TRUE(r.quality.watertight);
  EXPECT_DOUBLE_EQ(r.quality.penetration_mm3, 0.0);
}

// The same closed surface with every face below the middle of its height split in three at its
// centroid, `rounds` times over (9 faces for each after two).
SkullMesh densified_below(SkullMesh mesh, int rounds) {
  const auto [lo, hi] = mesh_bounds(mesh);
  const double middle = 0.5 * (lo.z() + hi.z());
  auto centre = [&](SkullMesh::FaceHandle fh) {
    const FaceCorners f = face_corners(mesh, fh);
    return Eigen::Vector3d((f.p[0] + f.p[1] + f.p[2]) / 3.0);
  };
  for (int round = 0; round < rounds; ++round) {
    std::vector<SkullMesh::FaceHandle> low;
    for (auto fh : mesh.faces())
      if (centre(fh).z() < middle) low.push_back(fh);
    for (auto fh : low) mesh.split(fh, to_point(centre(fh)));
  }
  return mesh;
}

// A skull whose triangles are dense in one part has its vertex centroid there: decimation keeps
// the detail of the base and the face and thins the smooth vault, and on a SkullFix skull
// decimated to 20 % the vertex centroid lay 11 mm low, in the bone of its base, where no ray
// passes through one table: no defect was found. An opening as wide as SkullFix's is seen from
// the surface's centroid (step 3 of docs/AUTOPLAN.md), the same for the same surface however it
// is meshed: here the lower half meshed nine times as densely moves the vertex centroid down by
// more than 10 mm and the rays' start not at all.
TEST(Autoplan, AWideOpeningIsSeenFromTheSameStartHoweverTheSkullIsMeshed) {
  InjectDefectParams p;
  p.shape = InjectDefectParams::Shape::Cube;
  p.center = test::head_surface_point(Eigen::Vector3d(0.0, -0.2, 1.0).normalized());
  p.size_mm = 90;
  p.voxel_mm = 0.5;
  const InjectDefectResult d = inject_defect(thick_head(), p);
  ASSERT_TRUE(d.usable());
  const SkullMesh& even = d.defective;
  const SkullMesh dense = densified_below(even, 2);
  ASSERT_GT(dense.n_faces(), 4 * even.n_faces());
  RecordProperty("vertex_centroid_moved_mm",
                 std::to_string((vertex_centroid(dense) - vertex_centroid(even)).norm()));
  EXPECT_GT((vertex_centroid(dense) - vertex_centroid(even)).norm(), 10.0);
  EXPECT_LT((surface_centroid(dense) - surface_centroid(even)).norm(), 1e-6);
  const Plane midline;  // x = 0: the head is symmetric about it
  const DefectRegion a = detect_defect_near_plane(even, SurfaceLocator(even), midline, {});
  const DefectRegion b = detect_defect_near_plane(dense, SurfaceLocator(dense), midline, {});
  ASSERT_TRUE(a.found()) << a.message;
  ASSERT_TRUE(b.found()) << b.message;
  EXPECT_LT((a.center - b.center).norm(), 1e-6);
  // The same opening (rays that graze its edge meet the finer triangles a little differently).
  EXPECT_NEAR(a.area_mm2, b.area_mm2, 0.01 * a.area_mm2);
}

// Pieces a mesh brings along (a headrest, a collar; the loader drops only those far from the
// skull) can pull the vertices' mean out of the cranial cavity, where no vault is seen from it.
// The vault's centre is then sought from the surface's centroid, and the rays start where they
// would without the piece: here a small, densely meshed sphere below the head, placed so that
// the vertices' mean lies 150 mm below the head's centre.
TEST(Autoplan, ADensePieceBelowTheSkullDoesNotMoveTheRaysStart) {
  const InjectDefectResult d = defect_at({0.75, 0.2, 0.6}, 45);
  ASSERT_TRUE(d.usable());
  TriangleSoup piece = to_soup(test::make_symmetric_head(7));
  const double n_head = static_cast<double>(d.defective.n_vertices());
  const double n_piece = static_cast<double>(piece.vertices.size());
  const double below = 150.0 * (n_head + n_piece) / n_piece;
  TriangleSoup both = to_soup(d.defective);
  const int first = static_cast<int>(both.vertices.size());
  for (const Eigen::Vector3d& v : piece.vertices)
    both.vertices.push_back(0.05 * v - below * Eigen::Vector3d::UnitZ());
  for (const Eigen::Vector3i& t : piece.triangles)
    both.triangles.push_back(t + Eigen::Vector3i::Constant(first));
  const SkullMesh with_piece = build_mesh(both);
  const Plane midline;  // x = 0: the head is symmetric about it
  EXPECT_LT(midline.project(vertex_centroid(with_piece)).z(), -140.0);
  const DefectRegion a =
      detect_defect_near_plane(d.defective, SurfaceLocator(d.defective), midline, {});
  const DefectRegion b =
      detect_defect_near_plane(with_piece, SurfaceLocator(with_piece), midline, {});
  ASSERT_TRUE(a.found()) << a.message;
  ASSERT_TRUE(b.found()) << b.message;
  EXPECT_LT((a.center - b.center).norm(), 0.1);
  // The same opening; the rays' lattice, turned by the vertices' principal axes (skull_frame),
  // which the piece moves too, meets its edge a little differently (1.3 %).
  EXPECT_NEAR(a.area_mm2, b.area_mm2, 0.03 * a.area_mm2);
}

// Beside the same oblique cut a ray from the centre that passes just outside the opening meets
// the cut face first, above where the inner table goes on. An inner support marker there would
// lift the implant's inner surface to the face and leave the wedge of bone below it empty (on
// SkullFix the implant thinned towards every side of the cube): every inner marker lies on the
// inner table the intact skull has along its ray.
TEST(Autoplan, InnerMarkersAtAnObliqueCutStayOnTheInnerTable) {
  const AutoplanResult& r = oblique_cut().plan;
  ASSERT_TRUE(r.planned()) << r.message;
  const SurfaceLocator truth(oblique_cut().intact);
  int inner = 0;
  double worst = 0.0;
  for (const auto& m : r.markers) {
    if (m.type != MarkerType::InnerSurface) continue;
    ++inner;
    const RayThroughBone t = tables_along(truth, r, m);
    ASSERT_TRUE(t.paired) << "inner marker " << m.id;
    const double off = (m.position - r.defect.center).norm() - (*t.inner - r.defect.center).norm();
    worst = std::max(worst, std::abs(off));
    EXPECT_LT(std::abs(off), 1.0) << "inner marker " << m.id << " is " << off
                                  << " mm off the inner table";
  }
  RecordProperty("worst_inner_marker_mm", std::to_string(worst));
  EXPECT_GE(inner, 20);
}

// Real data when present (../shared/data/skullfix; skipped otherwise): SkullFix case 000, a
// cube cut across the midline at the back of the head, planned from its NRRD mask alone against
// the ground-truth implant (figures in docs/AUTOPLAN.md).
TEST(Autoplan, SkullFixCaseAcrossTheMidlineMatchesTheGroundTruth) {
  const std::string dir = CRANIOPLAN_SKULLFIX_DIR;
  if (!std::filesystem::exists(dir + "/000_defective_skull.nrrd") ||
      !std::filesystem::exists(dir + "/000_implant.nrrd"))
    GTEST_SKIP() << "SkullFix data not present";
  const SkullMesh skull = load_skull(dir + "/000_defective_skull.nrrd").mesh;
  const AutoplanResult r = autoplan(skull, Landmarks{});
  ASSERT_TRUE(r.planned()) << r.message;
  EXPECT_EQ(r.method_used, PlanMethod::RimOnly);
  const SkullMesh truth = load_surface(dir + "/000_implant.nrrd").mesh;
  const CompareResult c = compare_implants(r.implant.mesh, truth, &skull);
  RecordProperty("dice", std::to_string(c.dice));
  RecordProperty("boundary_dice", std::to_string(c.boundary_dice));
  RecordProperty("hd95_mm", std::to_string(c.hd95_mm));
  EXPECT_GE(c.dice, 0.90);
  EXPECT_GE(c.boundary_dice, 0.91);
  EXPECT_LE(c.hd95_mm, 1.5);
  EXPECT_TRUE(r.quality.watertight);
}

// A plan of a defect the scan ended across: planned on its opening, its rim traced, the message
// and the quality report saying the bone beyond the scan is unknown, the implant ending at the
// scan's plane (not beyond, not short of it), printable with its rim on the bone.
void expect_planned_up_to_the_scans_end(const AutoplanResult& r) {
  ASSERT_TRUE(r.planned()) << r.message;
  EXPECT_TRUE(r.defect.rim_traced) << r.message;
  EXPECT_NE(r.message.find("the bone beyond the scan is unknown"), std::string::npos) << r.message;
  ASSERT_EQ(r.defect.scan_ends.size(), 1u) << r.message;
  const Plane end = r.defect.scan_ends[0];
  double beyond = -1e9;
  for (auto vh : r.implant.mesh.vertices())
    beyond = std::max(beyond, end.signed_distance(to_eigen(r.implant.mesh.point(vh))));
  EXPECT_LT(beyond, 1.0) << "built beyond the scan";
  EXPECT_GT(beyond, -1.0) << "ends at the scan's end, not short of it";
  EXPECT_TRUE(r.quality.printable)
      << (r.quality.reasons.empty() ? std::string() : r.quality.reasons[0]);
  EXPECT_LE(r.quality.rim_gap_mm, kRimGapTargetMm);
  EXPECT_TRUE(r.quality.ends_at_scan_end) << "the quality report says so";
}

// A 55 mm defect high on the right of a two-table head whose scan ended 12 mm inside the
// defect's centre (the importer padded it: a flat cap across the bone): planned on its
// opening up to the scan's end, printable, the implant ending at the plane, and as the removed
// bone scanned alike (measured Dice 0.903, HD95 1.8 mm).
TEST(Autoplan, ADefectTheScanEndsAcrossIsPlannedUpToTheScansEnd) {
  const Eigen::Vector3d direction = Eigen::Vector3d(-0.5, 0.1, 0.85).normalized();
  const InjectDefectResult d = defect_at(direction, 55);
  ASSERT_TRUE(d.usable());
  const Eigen::Vector3d at(test::head_surface_point(direction).x() - 12.0, 0.0, 0.0);
  const SkullMesh skull = test::scanned_padded(d.defective, at, Eigen::Vector3d::UnitX(), 0.5);
  const AutoplanResult r = autoplan(skull, Landmarks{});
  expect_planned_up_to_the_scans_end(r);
  if (HasFatalFailure()) return;
  const SkullMesh truth = test::scanned_padded(d.implant, at, Eigen::Vector3d::UnitX(), 0.5);
  const CompareResult c = compare_implants(r.implant.mesh, truth, &skull);
  RecordProperty("dice", std::to_string(c.dice));
  RecordProperty("hd95_mm", std::to_string(c.hd95_mm));
  EXPECT_GE(c.dice, 0.85) << "HD95 " << c.hd95_mm;
}

// A SkullFix volume whose field of view ends at row `rows` of j (towards the back of the head):
// the rows beyond are not in the scan.
Volume rows_scanned(const std::string& path, int rows) {
  const Volume whole = read_volume(path);
  Volume cut = whole;
  cut.dims[1] = std::min(rows, whole.dims[1]);
  cut.data.assign(cut.size(), 0.0f);
  for (int k = 0; k < cut.dims[2]; ++k)
    for (int j = 0; j < cut.dims[1]; ++j)
      for (int i = 0; i < cut.dims[0]; ++i) cut.data[cut.index(i, j, k)] = whole.at(i, j, k);
  return cut;
}

SkullMesh surface_of(const Volume& volume) {
  SkullMesh mesh;
  const ExtractBoneSurfaceResult r = extract_bone_surface(volume, {}, mesh);
  EXPECT_TRUE(r.usable()) << r.message;
  return mesh;
}

// SkullFix 000 scanned only up to row 390 of j: the field of view ends across the back of the
// head, through the defect (a fifth of it is beyond). The opening is told from the scan's end
// (its rim traced on the bone, and along the scan's end where the table would cross it), the
// implant is planned up to the scan's border and not beyond, printable, and the message says
// the bone beyond the scan is unknown. Dice against the ground truth cut alike: measured 0.881
// (0.03 below: the plan moves with the rays' start by about that much).
TEST(Autoplan, ADefectTheScansFieldOfViewCutsAcrossIsPlannedUpToTheScansEnd) {
  const std::string dir = CRANIOPLAN_SKULLFIX_DIR;
  if (!std::filesystem::exists(dir + "/000_defective_skull.nrrd") ||
      !std::filesystem::exists(dir + "/000_implant.nrrd"))
    GTEST_SKIP() << "SkullFix data not present";
  constexpr int kRows = 390;
  const SkullMesh skull = surface_of(rows_scanned(dir + "/000_defective_skull.nrrd", kRows));
  const AutoplanResult r = autoplan(skull, Landmarks{});
  expect_planned_up_to_the_scans_end(r);
  if (HasFatalFailure()) return;
  const SkullMesh truth = surface_of(rows_scanned(dir + "/000_implant.nrrd", kRows));
  const CompareResult c = compare_implants(r.implant.mesh, truth, &skull);
  RecordProperty("dice", std::to_string(c.dice));
  RecordProperty("hd95_mm", std::to_string(c.hd95_mm));
  EXPECT_GE(c.dice, 0.85) << "HD95 " << c.hd95_mm;
}

// The worst of the library's flaps in docs/AUTOPLAN.md's table, and the Dice it planned at
// (measured less 0.03: the plan moves with the rays' start by about that much).
constexpr const char* kWorstFlapSkull = "034_complete_skull.nrrd";
constexpr int kWorstFlap = 1;            // a right flap 145 × 105 mm, 16 mm off the midline
constexpr double kWorstFlapDice = 0.66;  // measured 0.696 (the registered mirror alone: 0.753)

// Real bone when present (../shared/data/skull-library, beside the SkullFix cases; skipped
// otherwise): the decompressive-craniectomy flap that planned worst of docs/AUTOPLAN.md's table
// (`study SKULL --shape flap --count 2`, the flap and skull below) is planned on its opening,
// with its whole edge seen, and printable.
TEST(Autoplan, TheWorstFlapOfTheLibraryIsPlannedAndPrintable) {
  const std::filesystem::path file = std::filesystem::path(CRANIOPLAN_SKULLFIX_DIR).parent_path() /
                                     "skull-library" / kWorstFlapSkull;
  if (!std::filesystem::exists(file)) GTEST_SKIP() << "skull library not present";
  const SkullMesh skull = load_skull(file.string()).mesh;
  const SurfaceLocator bone(skull);
  const PlaneFit plane = fit_sagittal_plane(skull, Landmarks{});
  ASSERT_TRUE(plane.usable()) << plane.message;
  // study's flap_series(false, kWorstFlap): sizes spread by the golden ratio.
  const double a = std::fmod(0.381966 * (kWorstFlap + 1), 1.0),
               b = std::fmod(0.618034 * (kWorstFlap + 1), 1.0);
  FlapPlacementParams fp;
  fp.side = kWorstFlap % 2 == 0 ? 1 : -1;
  fp.length_mm = 130.0 + 20.0 * a;
  fp.width_mm = 100.0 + 20.0 * b;
  fp.midline_margin_mm = 15.0 + 5.0 * b;
  fp.forward_deg = 5.0 + 10.0 * a;
  const FlapPlacement placed = place_flap(skull, bone, plane.plane, fp);
  ASSERT_TRUE(placed.cut.has_value()) << placed.message;
  InjectDefectParams ip;
  ip.shape = InjectDefectParams::Shape::Flap;
  ip.flap = *placed.cut;
  ip.voxel_mm = 0.5;
  const InjectDefectResult d = inject_defect(skull, ip);
  ASSERT_TRUE(d.usable()) << d.message;
  AutoplanParams params;
  params.propose.detect.near = placed.cut->apex + placed.outer_radius_mm * placed.cut->axis;
  const AutoplanResult r = autoplan(d.defective, Landmarks{}, params);
  ASSERT_TRUE(r.planned()) << r.message;
  EXPECT_TRUE(r.defect.rim_traced) << r.message;
  EXPECT_EQ(r.message.find("rim not seen"), std::string::npos) << r.message;
  EXPECT_TRUE(r.quality.printable)
      << (r.quality.reasons.empty() ? std::string() : r.quality.reasons[0]);
  EXPECT_LE(r.quality.rim_gap_mm, kRimGapTargetMm);
  const CompareResult c = compare_implants(r.implant.mesh, d.implant, &d.defective);
  RecordProperty("dice", std::to_string(c.dice));
  RecordProperty("hd95_mm", std::to_string(c.hd95_mm));
  EXPECT_GE(c.dice, kWorstFlapDice) << "HD95 " << c.hd95_mm;
}

// Two openings: the larger is planned unless a point near the other one says which is meant.
TEST(Autoplan, WithTwoOpeningsAPointChoosesWhichIsPlanned) {
  const InjectDefectResult first = defect_at({0.75, 0.2, 0.6}, 45);
  ASSERT_TRUE(first.usable());
  const InjectDefectParams small = defect_params({-0.6, -0.5, 0.6}, 35);
  const InjectDefectResult both = inject_defect(first.defective, small);
  ASSERT_TRUE(both.usable());

  const AutoplanResult largest = autoplan(both.defective, Landmarks{});
  ASSERT_TRUE(largest.planned()) << largest.message;
  EXPECT_EQ(largest.defect.other_openings, 1);
  EXPECT_NE(largest.message.find("1 other opening not planned"), std::string::npos)
      << largest.message;
  EXPECT_GT(largest.defect.axis.x(), 0.5) << "the larger opening is on the right (+x)";
  // A ray through the other one, for planning it next (autoplan --all-openings).
  ASSERT_EQ(largest.defect.other_axes.size(), 1u);
  EXPECT_LT(largest.defect.other_axes[0].x(), -0.3) << "the smaller opening, on the left";

  AutoplanParams params;
  params.propose.detect.near = small.center;
  const AutoplanResult chosen = autoplan(both.defective, Landmarks{}, params);
  ASSERT_TRUE(chosen.planned()) << chosen.message;
  EXPECT_LT(chosen.defect.axis.x(), -0.3) << "the smaller opening, on the left";
  const CompareResult c = compare_implants(chosen.implant.mesh, both.implant, &both.defective);
  EXPECT_GE(c.dice, 0.85);
}

// Bilateral defects, mirror images of each other (as after bilateral decompressions): each
// opening's mirror falls into the other, so the mirror cannot fill either (the issue's
// "bilateral" case). The larger is planned, the message names the other, and a point near it
// plans that one; both from the rim alone, each close to its own ground truth.
TEST(Autoplan, BilateralDefectsArePlannedOneByOneFromTheRim) {
  const InjectDefectResult first = defect_at({0.75, 0.2, 0.6}, 45);
  ASSERT_TRUE(first.usable());
  // Its mirror image, a little smaller: the right one is "the largest".
  const InjectDefectParams left = defect_params({-0.75, 0.2, 0.6}, 40);
  const InjectDefectResult both = inject_defect(first.defective, left);
  ASSERT_TRUE(both.usable());

  const AutoplanResult a = autoplan(both.defective, Landmarks{});
  ASSERT_TRUE(a.planned()) << a.message;
  EXPECT_GT(a.defect.axis.x(), 0.5) << "the larger opening, on the right";
  EXPECT_EQ(a.defect.other_openings, 1);
  EXPECT_NE(a.message.find("1 other opening not planned"), std::string::npos) << a.message;
  EXPECT_EQ(a.method_used, PlanMethod::RimOnly) << a.message;
  EXPECT_LT(a.mirror_coverage, 0.5);
  const CompareResult ca = compare_implants(a.implant.mesh, first.implant, &both.defective);
  EXPECT_GE(ca.dice, 0.85) << "HD95 " << ca.hd95_mm;

  AutoplanParams near_left;
  near_left.propose.detect.near = left.center;
  const AutoplanResult b = autoplan(both.defective, Landmarks{}, near_left);
  ASSERT_TRUE(b.planned()) << b.message;
  EXPECT_LT(b.defect.axis.x(), -0.5) << "the one near the point, on the left";
  EXPECT_EQ(b.method_used, PlanMethod::RimOnly) << b.message;
  // The left defect's truth: what the second cut removed.
  const CompareResult cb = compare_implants(b.implant.mesh, both.implant, &both.defective);
  EXPECT_GE(cb.dice, 0.85) << "HD95 " << cb.hd95_mm;
  EXPECT_TRUE(a.quality.watertight);
  EXPECT_TRUE(b.quality.watertight);
  RecordProperty("dice_right", std::to_string(ca.dice));
  RecordProperty("dice_left", std::to_string(cb.dice));
  RecordProperty("coverage_right", std::to_string(a.mirror_coverage));

  // Both at once: the same two plans, the plane and the global registration found once.
  const std::vector<AutoplanResult> all = autoplan_all_openings(both.defective, Landmarks{});
  ASSERT_EQ(all.size(), 2u);
  for (size_t k = 0; k < all.size(); ++k) {
    const AutoplanResult& alone = k == 0 ? a : b;
    ASSERT_TRUE(all[k].planned()) << all[k].message;
    EXPECT_NE(all[k].message.find("1 other opening, planned as well"), std::string::npos)
        << all[k].message;
    EXPECT_EQ(all[k].plane.plane.normal, a.plane.plane.normal);
    EXPECT_EQ(all[k].markers.size(), alone.markers.size());
    EXPECT_NEAR(all[k].quality.volume_mm3, alone.quality.volume_mm3,
                1e-6 * alone.quality.volume_mm3);
    EXPECT_GT(all[k].defect.axis.dot(alone.defect.axis), std::cos(M_PI / 180));
  }
  auto has_stage = [](const AutoplanResult& r, const std::string& name) {
    for (const auto& [stage, seconds] : r.stage_seconds)
      if (stage == name) return true;
    return false;
  };
  EXPECT_TRUE(has_stage(all[0], "plane"));
  EXPECT_FALSE(has_stage(all[1], "plane")) << "the second plan reuses the first's plane";
  EXPECT_TRUE(has_stage(all[1], "local register"));
}

// A skull file may come in any pose (an STL from another tool, a scan of a patient lying
// prone). Here the skull is turned so that its one-sided defect faces straight down, where a
// rule "the skull base is the opening below" would take the defect for the base and find no
// defect. The base is the opening facing away from the vault, and the rays are
// laid out in the skull's own frame: the plan is the same as in the upright pose.
TEST(Autoplan, TheSkullsPoseDoesNotChangeThePlan) {
  const Eigen::Vector3d direction = Eigen::Vector3d(0.75, 0.2, 0.6).normalized();
  const InjectDefectResult d = defect_at(direction, 45);
  ASSERT_TRUE(d.usable());
  const Eigen::Quaterniond down =
      Eigen::Quaterniond::FromTwoVectors(direction, -Eigen::Vector3d::UnitZ());
  RigidTransform pose;
  pose.rotation = (Eigen::AngleAxisd(0.7, Eigen::Vector3d::UnitZ()) * down).toRotationMatrix();
  pose.translation = {120.0, -40.0, 300.0};
  // Without landmarks: turned, this head's principal axes mix left-right with up-down (it is
  // nearly as wide as it is high), and the plane must still be found (docs/AUTOPLAN.md).
  const AutoplanResult upright = autoplan(d.defective, Landmarks{});
  const AutoplanResult turned = autoplan(test::transformed(d.defective, pose), Landmarks{});
  ASSERT_TRUE(upright.planned()) << upright.message;
  ASSERT_TRUE(turned.planned()) << turned.message;
  EXPECT_GT(turned.defect.axis.dot(-Eigen::Vector3d::UnitZ()), 0.9);  // it faces down
  EXPECT_GT(turned.defect.axis.dot(pose.rotation * upright.defect.axis), std::cos(M_PI / 36));
  EXPECT_NEAR(turned.defect.area_mm2, upright.defect.area_mm2, 0.05 * upright.defect.area_mm2);
  EXPECT_EQ(turned.method_used, upright.method_used);
  const SkullMesh back = test::transformed(turned.implant.mesh, pose.inverse());
  const CompareResult same = compare_implants(back, upright.implant.mesh, &d.defective);
  const CompareResult truth = compare_implants(back, d.implant, &d.defective);
  RecordProperty("dice_between_poses", std::to_string(same.dice));
  EXPECT_GE(same.dice, 0.95) << "HD95 " << same.hd95_mm;
  EXPECT_GE(truth.dice, 0.9) << "HD95 " << truth.hd95_mm;
}

TEST(Autoplan, IntactSkullGivesNoDefect) {
  const AutoplanResult r = autoplan(thick_head(), Landmarks{});
  EXPECT_EQ(r.status, AutoplanResult::Status::NoDefect);
  EXPECT_NE(r.message.find("no defect"), std::string::npos);
}

// The stages' outputs agree: support markers lie on the bone around the opening, edge markers
// on the rays through the detected rim (on the fitted outer surface, within a fraction of a
// millimetre of the bone's edge), surface markers over the opening on the fitted surfaces —
// here, a skull symmetric by construction, on the registered mirror.
// Where the rays do not see the rim (they graze the bone or meet other bone first, e.g. along
// an orbit) the outline is interpolated between rim points far apart, and the surgeon is told
// how long each such stretch is. Rim points every 6° on a circle of 30 mm (3.1 mm apart), with
// runs of 4, 3 and 2 points taken out (one across the loop's closing): gaps of 30°, 24° and 18°,
// i.e. chords of 15.5, 12.5 and 9.4 mm. Over 10 mm: the first two; over four times the median
// spacing as well (12.5 mm): the first.
TEST(Autoplan, UnseenStretchesOfTheRimAreMeasured) {
  std::vector<Eigen::Vector3d> rim;
  auto missing = [](int k) {
    return (k >= 10 && k < 14) || k >= 58 || k == 0 || (k >= 30 && k < 32);
  };
  for (int k = 0; k < 60; ++k)
    if (!missing(k))
      rim.emplace_back(30.0 * std::cos(k * M_PI / 30.0), 30.0 * std::sin(k * M_PI / 30.0), 5.0);
  const double chord30 = 60.0 * std::sin(15.0 * M_PI / 180.0),
               chord24 = 60.0 * std::sin(12.0 * M_PI / 180.0);
  const std::vector<RimStretch> over10 = unseen_rim_stretches(rim, 10.0, 0.0);
  ASSERT_EQ(over10.size(), 2u);
  EXPECT_NEAR(over10[0].length_mm(), chord30, 1e-9);
  EXPECT_NEAR(over10[1].length_mm(), chord24, 1e-9);
  // Each stretch runs between the two rim points around the gap: the longest from k = 9 to
  // k = 14 across the missing 10-13, the next from k = 57 to k = 1 across 58, 59 and 0.
  const auto on_circle = [](int k) {
    return Eigen::Vector3d(30.0 * std::cos(k * M_PI / 30.0), 30.0 * std::sin(k * M_PI / 30.0), 5.0);
  };
  EXPECT_LT((over10[0].from - on_circle(9)).norm(), 1e-9);
  EXPECT_LT((over10[0].to - on_circle(14)).norm(), 1e-9);
  EXPECT_LT((over10[1].from - on_circle(57)).norm(), 1e-9);
  EXPECT_LT((over10[1].to - on_circle(1)).norm(), 1e-9);
  const std::vector<RimStretch> reported = unseen_rim_stretches(rim);
  ASSERT_EQ(reported.size(), 1u);
  EXPECT_NEAR(reported[0].length_mm(), chord30, 1e-9);
  EXPECT_TRUE(unseen_rim_stretches({rim.front()}).empty());
}

TEST(Autoplan, StagesAreConsistent) {
  const InjectDefectResult d = defect_at({-0.7, 0.3, 0.6}, 40);
  const AutoplanResult r = autoplan(d.defective, Landmarks{});
  ASSERT_TRUE(r.planned()) << r.message;
  EXPECT_EQ(r.method_used, PlanMethod::Mirror);
  EXPECT_TRUE(r.defect.unseen_rim.empty()) << r.defect.message;  // a clean cut, seen all round
  // The mirror built as a mesh (as `pipeline` exports it): autoplan only moved the skull's locator.
  const SurfaceLocator bone(d.defective),
      mirror(transform_mesh(mirror_mesh(d.defective, r.plane.plane), r.registration.transform));
  const SurfaceLocator moved = bone.moved(r.mirror_motion);
  int edges = 0, support = 0, inside = 0;
  for (const auto& m : r.markers) {
    if (is_edge(m.type)) {
      ++edges;
      EXPECT_LT(bone.closest(m.position).distance, 0.5) << "edge marker " << m.id;
      const Eigen::Vector3d ray = (m.position - r.defect.center).normalized();
      double best = 1.0;
      for (const auto& p : r.defect.outer_rim)
        best = std::min(best, 1.0 - ray.dot((p - r.defect.center).normalized()));
      EXPECT_LT(best, 1e-9) << "edge marker " << m.id << " off the rays through the rim";
    } else if (m.surface == MarkerSurface::Original) {
      ++support;
      EXPECT_LT(bone.closest(m.position).distance, 0.05) << "support marker " << m.id;
    } else {
      ++inside;
      EXPECT_LT(mirror.closest(m.position).distance, 0.5) << "surface marker " << m.id;
      EXPECT_NEAR(moved.closest(m.position).distance, mirror.closest(m.position).distance, 1e-9);
    }
  }
  EXPECT_GE(edges, 10);
  EXPECT_GE(support, 10);
  EXPECT_GE(inside, 10);
  EXPECT_GE(r.stage_seconds.size(), 6u);
  EXPECT_LT(r.plane.plane.angle_to_deg(Plane{Eigen::Vector3d::UnitX(), 0}), 1.0);
}

}  // namespace
}  // namespace cranioplan
