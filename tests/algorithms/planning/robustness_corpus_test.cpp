// The skull meshes users bring, made from the sample CT as other programs make them: open where
// the scan ends, other thresholds, smoothed, decimated, re-meshed, cropped. Each is written as a
// binary STL by VTK and read back as a user's file is, planned automatically, and compared with
// the plan on the project's own import. The table it prints is docs/AUTOPLAN.md's.
#include <gtest/gtest.h>
#include <vtkCellArray.h>
#include <vtkDiscreteFlyingEdges3D.h>
#include <vtkImageData.h>
#include <vtkLinearSubdivisionFilter.h>
#include <vtkNew.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkQuadricClustering.h>
#include <vtkQuadricDecimation.h>
#include <vtkSTLWriter.h>
#include <vtkSmartPointer.h>
#include <vtkTriangleFilter.h>
#include <vtkWindowedSincPolyDataFilter.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <functional>
#include <iterator>
#include <map>
#include <string>
#include <vector>

#include "cranioplan/algorithms/geometry/distance_transform.h"
#include "cranioplan/algorithms/geometry/point_index.h"
#include "cranioplan/algorithms/geometry/voxelize_mesh.h"
#include "cranioplan/algorithms/io/load_skull.h"
#include "cranioplan/algorithms/io/mesh_report.h"
#include "cranioplan/algorithms/io/read_volume.h"
#include "cranioplan/algorithms/planning/autoplan.h"
#include "cranioplan/algorithms/quality/compare_implants.h"
#include "support/synthetic.h"
#include "support/test_files.h"
#include "support/vtk_meshes.h"

namespace cranioplan {
namespace {

using test::to_polydata;

// As Slicer's model smoothing: a windowed-sinc filter, the boundary left in place.
vtkSmartPointer<vtkPolyData> sinc_smoothed(vtkPolyData* in, double pass_band) {
  vtkNew<vtkWindowedSincPolyDataFilter> f;
  f->SetInputData(in);
  f->SetNumberOfIterations(20);
  f->SetPassBand(pass_band);
  f->NormalizeCoordinatesOn();
  f->BoundarySmoothingOff();
  f->FeatureEdgeSmoothingOff();
  f->NonManifoldSmoothingOn();
  f->Update();
  return f->GetOutput();
}

vtkSmartPointer<vtkPolyData> decimated(vtkPolyData* in, double keep) {
  vtkNew<vtkQuadricDecimation> f;
  f->SetInputData(in);
  f->SetTargetReduction(1.0 - keep);
  f->Update();
  return f->GetOutput();
}

// Re-meshed: vertex clustering on a grid of up to 300³ cells (VTK coarsens it to the number of
// points: the sample's triangles come out 2.2 mm long on average), new triangles that follow
// the bone but none of the CT's.
vtkSmartPointer<vtkPolyData> remeshed(vtkPolyData* in) {
  vtkNew<vtkQuadricClustering> f;
  f->SetInputData(in);
  f->SetNumberOfDivisions(300, 300, 300);
  f->Update();
  vtkNew<vtkTriangleFilter> t;
  t->SetInputData(f->GetOutput());
  t->Update();
  return t->GetOutput();
}

// Finer: every triangle split in four at its edges' midpoints (the same surface, edges halved,
// four times the triangles), as a mesh exported at a finer resolution.
vtkSmartPointer<vtkPolyData> subdivided(vtkPolyData* in) {
  vtkNew<vtkLinearSubdivisionFilter> f;
  f->SetInputData(in);
  f->SetNumberOfSubdivisions(1);
  f->Update();
  return f->GetOutput();
}

// As 3D Slicer's Segment Editor makes a skull model: the CT thresholded into a binary
// labelmap, padded by a voxel (so the surface closes where the scan ends), its boundary by
// discrete flying edges in voxel coordinates, smoothed there as Slicer's closed-surface
// conversion does (a windowed sinc of 20 iterations, pass band 10^(-4 × smoothing factor);
// Slicer's default factor is 0.5) and moved to the patient's frame by the volume's geometry.
vtkSmartPointer<vtkPolyData> segmentation_model(const Volume& ct, double threshold,
                                                double smoothing_factor) {
  vtkNew<vtkImageData> labelmap;
  labelmap->SetDimensions(ct.dims[0] + 2, ct.dims[1] + 2, ct.dims[2] + 2);
  labelmap->AllocateScalars(VTK_UNSIGNED_CHAR, 1);
  auto* label = static_cast<unsigned char*>(labelmap->GetScalarPointer());
  std::fill(label, label + labelmap->GetNumberOfPoints(), static_cast<unsigned char>(0));
  for (int k = 0; k < ct.dims[2]; ++k)
    for (int j = 0; j < ct.dims[1]; ++j)
      for (int i = 0; i < ct.dims[0]; ++i)
        if (ct.at(i, j, k) >= threshold)
          label[(static_cast<size_t>(k + 1) * (ct.dims[1] + 2) + (j + 1)) * (ct.dims[0] + 2) +
                (i + 1)] = 1;
  vtkNew<vtkDiscreteFlyingEdges3D> surface;
  surface->SetInputData(labelmap);
  surface->SetValue(0, 1.0);
  surface->ComputeNormalsOff();
  surface->ComputeGradientsOff();
  surface->Update();
  vtkSmartPointer<vtkPolyData> pd = surface->GetOutput();
  if (smoothing_factor > 0.0) pd = sinc_smoothed(pd, std::pow(10.0, -4.0 * smoothing_factor));
  vtkNew<vtkPoints> world;
  world->SetDataTypeToDouble();
  world->SetNumberOfPoints(pd->GetNumberOfPoints());
  for (vtkIdType p = 0; p < pd->GetNumberOfPoints(); ++p) {
    double ijk[3];
    pd->GetPoint(p, ijk);
    const Eigen::Vector3d w = ct.world(Eigen::Vector3d(ijk[0] - 1.0, ijk[1] - 1.0, ijk[2] - 1.0));
    world->SetPoint(p, w.x(), w.y(), w.z());
  }
  vtkNew<vtkPolyData> out;
  out->SetPoints(world);
  out->SetPolys(pd->GetPolys());
  return out;
}

// Written as a binary STL by VTK and read back as a user's file.
SkullMesh exported(vtkPolyData* pd, const std::string& path) {
  vtkNew<vtkSTLWriter> w;
  w->SetFileName(path.c_str());
  w->SetFileTypeToBinary();
  w->SetInputData(pd);
  w->Write();
  return load_skull(path).mesh;
}

// How far two skulls' bone agrees where an implant sits: the Dice of their inside (0.3 mm
// voxels) within `reach` mm of the implant. An export of the same surface gives 1; another
// threshold or a smoothing moves the tables, and an implant fitted to them moves with them.
double bone_agreement(const SkullMesh& a, const SkullMesh& b, const SkullMesh& implant,
                      double reach = 10.0) {
  const auto [lo, hi] = mesh_bounds(implant);
  const Eigen::Vector3d pad = Eigen::Vector3d::Constant(reach + 1.0);
  const VoxelGrid grid = VoxelGrid::covering(lo - pad, hi + pad, 0.3);
  const std::vector<uint8_t> in_a = voxelize_mesh(a, grid), in_b = voxelize_mesh(b, grid);
  const std::vector<float> to_implant =
      distance_to_mask(voxelize_mesh(implant, grid), grid, reach + 1.0);
  size_t na = 0, nb = 0, both = 0;
  for (size_t c = 0; c < in_a.size(); ++c)
    if (to_implant[c] <= reach) {
      na += in_a[c];
      nb += in_b[c];
      both += in_a[c] && in_b[c];
    }
  return na + nb > 0 ? 2.0 * static_cast<double>(both) / static_cast<double>(na + nb) : 1.0;
}

struct Row {
  std::string name;
  bool planned = false, printable = false;
  double rim_gap_mm = -1, overlap_mm3 = -1, dice = 0;
  double same_threshold_dice = 0;       // against the own import's plan at the export's threshold
  double bone = 0, same_rays_dice = 0;  // bone_agreement; Dice planned with the own rays
  double centre_moved_mm = -1;          // the rays' centre from the own import's
  double frame_turned_deg = -1;         // the rays' lattice (skull_frame) from the own import's
  std::string message, why;
};

// What the issue asks of every export (docs/AUTOPLAN.md).
constexpr double kMaxRimGapMm = 0.5, kMaxOverlapMm3 = 5.0, kTargetDice = 0.90;
// The same defect planned (a plan of another opening has Dice 0 against it).
constexpr double kSameDefectDice = 0.8;
// The export whose bone itself moved too far for the Dice target (open at 450 HU: the tables
// thinner, the opening 72 mm² larger where thin bone by the orbit is gone; with the own plan's
// rays 0.877), measured 0.879: a floor under it, so that a change that again loses the rim
// along the frontal sinus (0.843 when a ray could cross only 15 mm of bone) fails here.
constexpr double kMovedBoneDice = 0.87;
// The own import's bone where the implant sits (bone_agreement): measured 0.980-1.000 on the
// exports of its surface (re-meshed on 0.8 mm cells the lowest), 0.906-0.971 on other
// thresholds and smoothings.
constexpr double kSameBone = 0.975;

// The exports are planned in three shards (three ctest entries that run beside each other), each
// with the own import's plan; the exports made at one threshold share a shard, so that the own
// import's plan at that threshold is made once.
constexpr int kExportShards = 3;
constexpr int kShardOfExport[] = {0, 0, 2, 1, 1, 1, 1, 0, 0, 0, 2, 1, 1, 2, 2, 2, 2};

class ExportsOfTheSample : public ::testing::TestWithParam<int> {};

TEST_P(ExportsOfTheSample, ArePlannedOnTheBone) {
  const int shard = GetParam();
  const std::string path = sample_case_path();
  if (!std::filesystem::exists(path))
    GTEST_SKIP() << path << " not installed (scripts/install-deps)";
  const test::TempDir dir;
  const LoadedSkull own = load_skull(path);
  const AutoplanResult reference = autoplan(own.mesh, Landmarks{});
  ASSERT_TRUE(reference.planned()) << reference.message;
  // Each export planned a second time with the rays where the own import's plan cast them
  // (its centre and frame): what the surface changes once the rays start alike.
  AutoplanParams own_rays;
  own_rays.propose.detect.center = reference.defect.center;
  own_rays.propose.detect.frame = reference.defect.frame;

  // The scan's lowest slice is at z = 0; the padding closed the import below it.
  auto open = [&](double threshold) {
    ExtractBoneSurfaceParams import;
    import.threshold = threshold;
    const SkullMesh closed = load_skull(path, import).mesh;
    return to_polydata(
        test::cut_open(closed, Eigen::Vector3d(0, 0, -1e-3), Eigen::Vector3d::UnitZ()));
  };
  const vtkSmartPointer<vtkPolyData> open300 = open(300.0);
  const Volume ct = read_volume(path);
  struct Case {
    std::string name;
    std::function<vtkSmartPointer<vtkPolyData>()> make;
    // Planned on the bone: planned, printable, rim gap and overlap within the limits, and the
    // defect the own import's plan found (Dice ≥ kSameDefectDice; planning another opening
    // gives 0). Meets the Dice target too. As measured; the table shows the rest.
    bool on_bone, meets_dice;
    // The own import's bone where the implant sits (bone_agreement ≥ kSameBone): planned with
    // the own plan's rays it meets the Dice target — all but where the rays start depends on
    // the bone, not on its triangles (measured 0.943-0.992).
    bool same_bone;
    // The CT threshold the export's bone was made at (HU): its plan is also compared with the
    // plan on the project's own import at that threshold, which has the same bone.
    double threshold = 300.0;
  };
  const std::vector<Case> cases = {
      {"open, 200 HU", [&] { return open(200.0); }, true, true, false, 200.0},
      {"open, 226 HU (InVesalius bone)", [&] { return open(226.0); }, true, true, false, 226.0},
      {"open, 300 HU", [&] { return open300; }, true, true, true},
      {"open, 400 HU", [&] { return open(400.0); }, true, true, false, 400.0},
      {"open, 450 HU", [&] { return open(450.0); }, true, false, false, 450.0},
      // The importer's own surface at 450 HU, closed by the padding as it comes (and as 3D
      // Slicer's closed surfaces are): capped where the scan ended and where it clips the
      // sides of the head. Its foramen magnum, seen through the scan's end, was planned before
      // caps were taken for the scan's end.
      {"closed (padded), 450 HU",
       [&] {
         ExtractBoneSurfaceParams import;
         import.threshold = 450.0;
         return to_polydata(load_skull(path, import).mesh);
       },
       true, true, false, 450.0},
      // The CT segmented and made a model in 3D Slicer (closed, stair-stepped then smoothed):
      // at 300 HU and at InVesalius's bone threshold, Slicer's default smoothing. At 300 HU
      // the fit 4 mm over the bone stands 1.07 mm off it over one 5° arc by the frontal sinus;
      // the fit from 5 mm meets it (ASlicerSegmentationIsFittedFromTheMarginThatMeetsTheBone).
      {"3D Slicer segmentation, 300 HU, smoothing 0.5",
       [&] { return segmentation_model(ct, 300.0, 0.5); }, true, true, false},
      {"3D Slicer segmentation, 226 HU, smoothing 0.5",
       [&] { return segmentation_model(ct, 226.0, 0.5); }, true, true, false, 226.0},
      {"open, sinc pass band 0.1", [&] { return sinc_smoothed(open300, 0.1); }, true, true, false},
      {"open, sinc pass band 0.01", [&] { return sinc_smoothed(open300, 0.01); }, true, true,
       false},
      {"open, sinc pass band 0.001", [&] { return sinc_smoothed(open300, 0.001); }, true, true,
       false},
      {"open, decimated to 50 %", [&] { return decimated(open300, 0.5); }, true, true, true},
      {"open, decimated to 25 %", [&] { return decimated(open300, 0.25); }, true, true, true},
      {"open, re-meshed (vertex clustering)", [&] { return remeshed(open300); }, true, true, true},
      {"open, subdivided (edges halved)", [&] { return subdivided(open300); }, true, true, true},
      {"cropped above the orbits (z ≥ 60 mm)",
       [&] {
         const SkullMesh m = load_skull(path).mesh;
         return to_polydata(
             test::cut_open(m, Eigen::Vector3d(0, 0, 60.0), Eigen::Vector3d::UnitZ()));
       },
       true, true, true},
      // A gantry tilted 20° (or a skull cropped obliquely by an exporter): the cut rises
      // towards the back, through the orbits at the front, in no axis's plane.
      {"cropped along a plane tilted 20° (gantry tilt)",
       [&] {
         const SkullMesh m = load_skull(path).mesh;
         const MeshReport box = report_mesh(m);
         const double tilt = 20.0 * M_PI / 180.0;
         return to_polydata(test::cut_open(
             m, Eigen::Vector3d(0, 0.5 * (box.bbox_min.y() + box.bbox_max.y()), 60.0),
             Eigen::Vector3d(0, -std::sin(tilt), std::cos(tilt))));
       },
       true, true, true},
  };
  // The own import's plan at each threshold an export was made at.
  std::map<double, AutoplanResult> at_threshold;
  auto own_plan_at = [&](double threshold) -> const AutoplanResult& {
    if (threshold == 300.0) return reference;
    auto it = at_threshold.find(threshold);
    if (it == at_threshold.end()) {
      ExtractBoneSurfaceParams import;
      import.threshold = threshold;
      it = at_threshold.emplace(threshold, autoplan(load_skull(path, import).mesh, Landmarks{}))
               .first;
    }
    return it->second;
  };
  ASSERT_EQ(cases.size(), std::size(kShardOfExport));
  std::vector<Row> rows;
  for (size_t i = 0; i < cases.size(); ++i) {
    if (kShardOfExport[i] != shard) continue;
    const Case& c = cases[i];
    SCOPED_TRACE(c.name);
    Row row;
    row.name = c.name;
    // CRANIOPLAN_KEEP_CORPUS=DIR keeps the exports (case0.stl ...) to plan them by hand.
    const char* keep = std::getenv("CRANIOPLAN_KEEP_CORPUS");
    const std::string file = "case" + std::to_string(i) + ".stl";
    const SkullMesh skull =
        exported(c.make(), keep ? std::string(keep) + "/" + file : dir.path(file));
    const AutoplanResult r = autoplan(skull, Landmarks{});
    row.planned = r.planned();
    row.message = r.message;
    if (r.planned()) {
      row.printable = r.quality.printable;
      row.rim_gap_mm = r.quality.rim_gap_mm;
      row.overlap_mm3 = r.quality.penetration_mm3;
      row.dice = compare_implants(r.implant.mesh, reference.implant.mesh).dice;
      const AutoplanResult& same_threshold = own_plan_at(c.threshold);
      EXPECT_TRUE(same_threshold.planned()) << same_threshold.message;
      row.same_threshold_dice = compare_implants(r.implant.mesh, same_threshold.implant.mesh).dice;
      row.centre_moved_mm = (r.defect.center - reference.defect.center).norm();
      const Eigen::Matrix3d turn = reference.defect.frame.transpose() * r.defect.frame;
      row.frame_turned_deg =
          std::acos(std::clamp(0.5 * (turn.trace() - 1.0), -1.0, 1.0)) * 180.0 / M_PI;
      if (!r.quality.reasons.empty()) row.why = r.quality.reasons[0];
    }
    row.bone = bone_agreement(own.mesh, skull, reference.implant.mesh);
    const AutoplanResult same_rays = autoplan(skull, Landmarks{}, own_rays);
    if (same_rays.planned())
      row.same_rays_dice = compare_implants(same_rays.implant.mesh, reference.implant.mesh).dice;
    if (c.same_bone) {
      EXPECT_GE(row.bone, kSameBone);
      EXPECT_GE(row.same_rays_dice, kTargetDice);
    }
    // Every export ends in a plan or in a message that says why not.
    EXPECT_TRUE(r.planned() || !r.message.empty());
    if (c.on_bone) {
      EXPECT_TRUE(row.planned) << r.message;
      EXPECT_TRUE(row.printable) << (r.quality.reasons.empty() ? "" : r.quality.reasons[0]);
      EXPECT_LE(row.rim_gap_mm, kMaxRimGapMm);
      EXPECT_LE(row.overlap_mm3, kMaxOverlapMm3);
      EXPECT_GE(row.dice, kSameDefectDice);
    }
    EXPECT_GE(row.dice, c.meets_dice ? kTargetDice : kMovedBoneDice);
    // Against the plan on the own import with the same bone (the export's threshold), every
    // export meets the Dice target: what it changes besides the threshold is how the file was
    // cut, smoothed or meshed.
    EXPECT_GE(row.same_threshold_dice, kTargetDice);
    rows.push_back(row);
  }
  std::printf(
      "\n| export of Cranium.inv3 | planned | printable | rim gap (mm) | overlap (mm³) | "
      "Dice vs own import | all met | Dice vs own import at the export's threshold | bone "
      "near the implant vs own import (Dice) | Dice with the own plan's rays | rays' centre "
      "moved (mm) | rays' lattice turned (°) "
      "|\n|---|---|---|---|---|---|---|---|---|---|---|---|\n");
  for (const Row& row : rows) {
    const bool all = row.planned && row.printable && row.rim_gap_mm <= kMaxRimGapMm &&
                     row.overlap_mm3 <= kMaxOverlapMm3 && row.dice >= kTargetDice;
    if (row.planned)
      std::printf(
          "| %s | yes | %s | %.2f | %.1f | %.3f | %s | %.3f | %.3f | %.3f | %.1f | %.1f |\n",
          row.name.c_str(), row.printable ? "yes" : "no", row.rim_gap_mm, row.overlap_mm3, row.dice,
          all ? "yes" : "no", row.same_threshold_dice, row.bone, row.same_rays_dice,
          row.centre_moved_mm, row.frame_turned_deg);
    else
      std::printf("| %s | no: %.120s | | | | | no | | %.3f | %.3f | | |\n", row.name.c_str(),
                  row.message.c_str(), row.bone, row.same_rays_dice);
    if (row.planned && !row.printable)
      std::printf("|  | not printable: %.160s | | | | | | | | | | |\n", row.why.c_str());
  }
}

INSTANTIATE_TEST_SUITE_P(RobustnessCorpus, ExportsOfTheSample, ::testing::Range(0, kExportShards));

// The sample segmented in 3D Slicer at 300 HU (smoothing 0.5): fitted 4 mm over the bone, the
// implant's edge stands 1.07 mm off the bone over one 5° arc at its lower medial corner, where
// the shell's last piece stops short of a fragment of the sinus wall. The fit from the next
// margin (5 mm) meets the bone there; the build says so, and a plan made without the search
// (build_implant commands before version 13) keeps the gap. The case as propose_markers 6 and
// build_implant 13 made it (inner support markers however thick the ring, the shell 0.3 mm
// thick before the fit); today's plan meets the bone from 4 mm already (0.13 mm).
TEST(RobustnessCorpus, ASlicerSegmentationIsFittedFromTheMarginThatMeetsTheBone) {
  const std::string path = sample_case_path();
  if (!std::filesystem::exists(path))
    GTEST_SKIP() << path << " not installed (scripts/install-deps)";
  const test::TempDir dir;
  const SkullMesh skull =
      exported(segmentation_model(read_volume(path), 300.0, 0.5), dir.path("slicer.stl"));
  const AutoplanResult today = autoplan(skull, Landmarks{});
  ASSERT_TRUE(today.planned()) << today.message;
  EXPECT_TRUE(today.quality.printable) << today.quality.reasons.front();
  EXPECT_LE(today.quality.rim_gap_mm, kRimGapTargetMm);
  AutoplanParams before;
  before.propose.max_support_layers = 0.0;
  before.implant.fit_keeps_shell_thick = false;
  const AutoplanResult r = autoplan(skull, Landmarks{}, before);
  ASSERT_TRUE(r.planned()) << r.message;
  EXPECT_TRUE(r.quality.printable) << r.quality.reasons.front();
  EXPECT_LE(r.quality.rim_gap_mm, kRimGapTargetMm);
  EXPECT_EQ(r.implant.fit_to_bone_used_mm, 5.0);
  EXPECT_NE(r.implant.message.find("built 5 mm over the bone instead of 4: at 4 mm its edge "
                                   "stood 1.0"),
            std::string::npos)
      << r.implant.message;
  AutoplanParams as_asked = before;
  as_asked.implant.fit_margin_search = false;
  const AutoplanResult kept = autoplan(skull, Landmarks{}, as_asked);
  ASSERT_TRUE(kept.planned()) << kept.message;
  EXPECT_EQ(kept.implant.fit_to_bone_used_mm, 4.0);
  EXPECT_GT(kept.quality.rim_gap_mm, 1.0);
  ASSERT_TRUE(kept.quality.rim_gap_at.has_value());
  // The gap it closed is where the build said it stood.
  const std::string at = r.implant.message.substr(r.implant.message.rfind(" at ("));
  char expected[64];
  std::snprintf(expected, sizeof(expected), " at (%.1f, %.1f, %.1f) mm",
                kept.quality.rim_gap_at->x(), kept.quality.rim_gap_at->y(),
                kept.quality.rim_gap_at->z());
  EXPECT_EQ(at, expected);
}

// The sample as InVesalius itself meshed it: the project stores the bone surface InVesalius 3
// made in 2012 (surface_0.vtp: its own marching cubes, smoothing and decimation, at its own
// threshold, 352,000 triangles with a piece of the table and holes of its own), which is what
// an InVesalius user exports. Its coordinates are InVesalius's: the project's voxel (i, j, k)
// at (i·sx, −j·sy, k·sz), the patient's LPS up to a translation, which is the origin the
// project's import is given (docs/FRAMES.md). A third-party check of that frame: moved by the
// origin, most of its vertices lie on the import's surface, and mirrored across y they do not.
// And it is planned as the import is: the same defect, on the patient's right and in front,
// printable, on the bone (measured: Dice 0.942, rim gap 0.09 mm, no overlap).
TEST(RobustnessCorpus, InVesaliussOwnSurfaceOfTheSampleIsPlannedLikeItsImport) {
  const std::string path = sample_case_path();
  if (!std::filesystem::exists(path))
    GTEST_SKIP() << path << " not installed (scripts/install-deps)";
  const test::TempDir dir;
  // The project is a gzipped tar; its folder's name is InVesalius's temporary one.
  ASSERT_EQ(test::run_command("tar xzf " + path + " -C " + dir.path("") +
                              " --wildcards '*surface_0.vtp'"),
            0);
  std::string surface;
  for (const auto& e : std::filesystem::recursive_directory_iterator(dir.path("")))
    if (e.path().filename() == "surface_0.vtp") surface = e.path().string();
  ASSERT_FALSE(surface.empty()) << "the project holds its bone surface";
  const LoadedSkull theirs = load_skull(surface);
  const LoadedSkull own = load_skull(path);
  const Volume ct = read_volume(path);
  const Eigen::Vector3d to_lps = ct.origin;
  EXPECT_GT(to_lps.y(), 200.0) << "the rows' far end";
  size_t on = 0, mirrored_on = 0, n = 0;
  const PointIndex own_vertices(all_vertex_samples(own.mesh).points);
  for (auto vh : theirs.mesh.vertices()) {
    if (vh.idx() % 10 != 0) continue;
    const Eigen::Vector3d p = to_eigen(theirs.mesh.point(vh));
    double d2 = 0, m2 = 0;
    own_vertices.nearest(p + to_lps, &d2);
    own_vertices.nearest(Eigen::Vector3d(p.x(), -p.y(), p.z()), &m2);
    on += d2 < 1.0;
    mirrored_on += m2 < 1.0;
    ++n;
  }
  EXPECT_GT(static_cast<double>(on) / n, 0.8);
  EXPECT_LT(static_cast<double>(mirrored_on) / n, 0.2);

  const AutoplanResult reference = autoplan(own.mesh, Landmarks{});
  ASSERT_TRUE(reference.planned()) << reference.message;
  AutoplanParams params;
  take_scan_borders(params.propose.detect, theirs.report);
  const AutoplanResult r = autoplan(theirs.mesh, Landmarks{}, params);
  ASSERT_TRUE(r.planned()) << r.message;
  EXPECT_EQ(r.method_used, PlanMethod::Mirror);
  EXPECT_TRUE(test::on_the_patients_right_in_front(r.plane.plane, r.defect));
  EXPECT_TRUE(r.quality.printable) << (r.quality.reasons.empty() ? "" : r.quality.reasons[0]);
  EXPECT_LE(r.quality.rim_gap_mm, kMaxRimGapMm);
  EXPECT_LE(r.quality.penetration_mm3, kMaxOverlapMm3);
  const CompareResult same = compare_implants(
      test::transformed(r.implant.mesh, RigidTransform::from_axis_angle({0, 0, 1}, 0.0, to_lps)),
      reference.implant.mesh);
  RecordProperty("dice", std::to_string(same.dice));
  RecordProperty("rim_gap_mm", std::to_string(r.quality.rim_gap_mm));
  EXPECT_GE(same.dice, kTargetDice) << "HD95 " << same.hd95_mm;
}

// How much the plan moves with its own rays: the sample's own import planned again with the
// rays' centre moved 1 mm along each axis, and with their lattice turned 3° either way about
// the midsagittal plane's normal. Every export starts from this spread (docs/AUTOPLAN.md).
TEST(RobustnessCorpus, HowFarThePlanMovesWithItsOwnRays) {
  const std::string path = sample_case_path();
  if (!std::filesystem::exists(path))
    GTEST_SKIP() << path << " not installed (scripts/install-deps)";
  const SkullMesh skull = load_skull(path).mesh;
  const AutoplanResult reference = autoplan(skull, Landmarks{});
  ASSERT_TRUE(reference.planned()) << reference.message;
  const Eigen::Vector3d center = reference.defect.center;
  const Eigen::Matrix3d frame = reference.defect.frame;
  struct Move {
    std::string name;
    Eigen::Vector3d shift;
    double turn_deg;
  };
  std::vector<Move> moves;
  for (int axis = 0; axis < 3; ++axis)
    for (double sign : {1.0, -1.0})
      moves.push_back({std::string(sign > 0 ? "+" : "-") + "xyz"[axis] + " 1 mm",
                       sign * Eigen::Vector3d::Unit(axis), 0.0});
  moves.push_back({"turned +3°", Eigen::Vector3d::Zero(), 3.0});
  moves.push_back({"turned -3°", Eigen::Vector3d::Zero(), -3.0});
  std::printf("\n| rays | Dice vs unmoved | rim gap (mm) | printable |\n|---|---|---|---|\n");
  double sum = 0.0;
  for (const Move& m : moves) {
    SCOPED_TRACE(m.name);
    AutoplanParams params;
    params.propose.detect.center = center + m.shift;
    params.propose.detect.frame =
        Eigen::AngleAxisd(m.turn_deg * M_PI / 180.0, reference.plane.plane.normal) * frame;
    const AutoplanResult r = autoplan(skull, Landmarks{}, params);
    ASSERT_TRUE(r.planned()) << r.message;
    const double dice = compare_implants(r.implant.mesh, reference.implant.mesh).dice;
    sum += dice;
    std::printf("| %s | %.3f | %.2f | %s |\n", m.name.c_str(), dice, r.quality.rim_gap_mm,
                r.quality.printable ? "yes" : "no");
    EXPECT_TRUE(r.quality.printable) << (r.quality.reasons.empty() ? "" : r.quality.reasons[0]);
    // Measured 0.938-0.972 (0.911-0.963 with every fitting site weighed alike, 0.915-0.941
    // with rays that could cross only 15 mm of bone as well): a floor below it, so that a
    // change that makes the plan follow its rays more fails here.
    EXPECT_GE(dice, 0.925);
  }
  std::printf("mean Dice %.3f\n", sum / static_cast<double>(moves.size()));
}

// A SkullFix case (skipped when ../shared is absent) as an exporter gives it: its mask meshed,
// open where the scan's cube ends below, decimated to a quarter; planned on the bone and against
// the ground truth as the own import is.
TEST(RobustnessCorpus, ASkullFixCaseOpenAndDecimatedIsPlannedOnTheBone) {
  const std::string dir = CRANIOPLAN_SKULLFIX_DIR;
  if (!std::filesystem::exists(dir + "/001_defective_skull.nrrd") ||
      !std::filesystem::exists(dir + "/001_implant.nrrd"))
    GTEST_SKIP() << "SkullFix data not present";
  const test::TempDir tmp;
  const SkullMesh own = load_skull(dir + "/001_defective_skull.nrrd").mesh;
  const MeshReport rep = report_mesh(own);
  // As if the scan had ended 10 mm above the mask's lowest slice (the padding closes the mask
  // itself there, and the bone meets the cube's floor only along a short stretch).
  const SkullMesh open =
      test::cut_open(own, rep.bbox_min + Eigen::Vector3d(0, 0, 10.0), Eigen::Vector3d::UnitZ());
  ASSERT_GT(report_mesh(open).boundary_edges, 100);
  const SkullMesh skull = exported(decimated(to_polydata(open), 0.25), tmp.path("001.stl"));
  const AutoplanResult reference = autoplan(own, Landmarks{});
  ASSERT_TRUE(reference.planned()) << reference.message;
  const AutoplanResult r = autoplan(skull, Landmarks{});
  ASSERT_TRUE(r.planned()) << r.message;
  EXPECT_TRUE(r.quality.printable) << (r.quality.reasons.empty() ? "" : r.quality.reasons[0]);
  // Measured 0.15 mm (0.62 mm when the rim stopped short of a corner of the cube's cut with
  // its burr hole: docs/IMPLANT.md, "Fitting to the bone").
  EXPECT_LE(r.quality.rim_gap_mm, kMaxRimGapMm);
  EXPECT_LE(r.quality.penetration_mm3, kMaxOverlapMm3);
  const SkullMesh truth = load_surface(dir + "/001_implant.nrrd").mesh;
  const CompareResult own_truth = compare_implants(reference.implant.mesh, truth);
  const CompareResult truth_c = compare_implants(r.implant.mesh, truth);
  const CompareResult vs_own = compare_implants(r.implant.mesh, reference.implant.mesh);
  std::printf(
      "SkullFix 001 open, decimated to 25 %%: rim gap %.2f mm, overlap %.1f mm3, Dice %.3f "
      "vs own import, %.3f vs truth (own import %.3f)\n",
      r.quality.rim_gap_mm, r.quality.penetration_mm3, vs_own.dice, truth_c.dice, own_truth.dice);
  EXPECT_GE(vs_own.dice, kTargetDice);
  EXPECT_GE(truth_c.dice, own_truth.dice - 0.01);
}

}  // namespace
}  // namespace cranioplan
