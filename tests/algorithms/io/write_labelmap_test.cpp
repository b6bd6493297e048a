#include "cranioplan/algorithms/io/write_labelmap.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <filesystem>

#include "cranioplan/algorithms/geometry/surface_locator.h"
#include "cranioplan/algorithms/geometry/voxelize_mesh.h"
#include "cranioplan/algorithms/io/load_skull.h"
#include "cranioplan/algorithms/io/read_volume.h"
#include "cranioplan/algorithms/planning/autoplan.h"
#include "cranioplan/model/error.h"
#include "support/synthetic.h"
#include "support/test_files.h"

namespace cranioplan {
namespace {

// A sphere of radius `r` about `c`, from the finely subdivided synthetic head.
SkullMesh sphere(double r, const Eigen::Vector3d& c) {
  TriangleSoup s = to_soup(test::make_symmetric_head(5));
  for (auto& p : s.vertices) p = c + r * p.normalized();
  return build_mesh(s);
}

double dice(const std::vector<uint8_t>& a, const std::vector<uint8_t>& b) {
  long long both = 0, sum = 0;
  for (size_t i = 0; i < a.size(); ++i) {
    both += a[i] && b[i];
    sum += a[i] + b[i];
  }
  return sum ? 2.0 * static_cast<double>(both) / static_cast<double>(sum) : 1.0;
}

// On an oblique, sheared grid every sample is inside exactly when it lies in the ball, but for
// samples within the polygon's sag of the sphere (0.05 mm here).
TEST(WriteLabelmap, ABallOnAnObliqueGridIsLabelledWhereTheGeometrySays) {
  const Eigen::Vector3d c(-20, 35, 110);
  Volume grid = test::oblique_ball_volume(c);
  grid.directions.col(2) += 0.2 * grid.directions.col(0);  // shear the grid too
  const SkullMesh ball = sphere(9.0, c);
  const std::vector<uint8_t> labels = labelmap_on_grid(ball, grid);
  long long wrong = 0, inside = 0;
  for (int k = 0; k < grid.dims[2]; ++k)
    for (int j = 0; j < grid.dims[1]; ++j)
      for (int i = 0; i < grid.dims[0]; ++i) {
        const double d = (grid.world(Eigen::Vector3d(i, j, k)) - c).norm();
        const bool label = labels[grid.index(i, j, k)] != 0;
        inside += label;
        if (std::abs(d - 9.0) > 0.05) wrong += label != (d < 9.0);
      }
  EXPECT_EQ(wrong, 0);
  EXPECT_GT(inside, 1000);
  // A mesh beside the grid labels nothing.
  const std::vector<uint8_t> none =
      labelmap_on_grid(sphere(5.0, c + Eigen::Vector3d(500, 0, 0)), grid);
  EXPECT_EQ(std::count(none.begin(), none.end(), 1), 0);
}

// Written, the file is read back by our reader and by teem's unu (the NRRD format's reference
// implementation, when installed) with the same grid and the same labels.
TEST(WriteLabelmap, TheFileReadsBackToTheSameGridAndLabels) {
  test::TempDir dir;
  const Eigen::Vector3d c(10, -20, 30);
  const Volume grid = test::oblique_ball_volume(c);
  const std::vector<uint8_t> labels = labelmap_on_grid(sphere(8.0, c), grid);
  for (const char* name : {"implant.nrrd", "implant.seg.nrrd"}) {
    const std::string path = dir.path(name);
    write_labelmap_nrrd(labels, grid, path, {"plate", {1, 0.5, 0}});
    const Volume back = read_volume(path);
    EXPECT_EQ(back.dims, grid.dims);
    EXPECT_LT((back.directions - grid.directions).norm(), 1e-12);
    EXPECT_LT((back.origin - grid.origin).norm(), 1e-12);
    EXPECT_EQ(back.kind, VolumeKind::Mask);
    ASSERT_EQ(back.data.size(), labels.size());
    for (size_t i = 0; i < labels.size(); ++i) ASSERT_EQ(back.data[i], labels[i]) << i;
    if (test::run_command("command -v teem-unu >/dev/null") == 0) {
      const std::string raw = dir.path(std::string("raw-") + name);
      ASSERT_EQ(
          test::run_command("teem-unu save -i '" + path + "' -f nrrd -e raw -o '" + raw + "'"), 0);
      const std::string bytes = test::read_bytes(raw);
      ASSERT_GE(bytes.size(), labels.size());
      EXPECT_EQ(bytes.substr(bytes.size() - labels.size()),
                std::string(labels.begin(), labels.end()))
          << "teem reads the same labels";
    }
  }
  const std::string seg = test::read_bytes(dir.path("implant.seg.nrrd"));
  EXPECT_NE(seg.find("Segment0_Name:=plate\n"), std::string::npos);
  EXPECT_NE(seg.find("Segment0_Color:=1 0.5 0\n"), std::string::npos);
  EXPECT_EQ(test::read_bytes(dir.path("implant.nrrd")).find("Segment0"), std::string::npos);
  EXPECT_THROW(write_labelmap_nrrd({1, 0}, grid, dir.path("short.nrrd")), InputError);
}

// The crossings of the surface along an oblique ray from `p`: odd inside a closed surface.
int crossings(const SurfaceLocator& locator, Eigen::Vector3d p, double reach) {
  const Eigen::Vector3d dir = Eigen::Vector3d(0.83, 0.41, 0.38).normalized();
  int n = 0;
  while (const auto hit = locator.first_hit(p, p + reach * dir)) {
    ++n;
    p = hit->point + 1e-6 * dir;
  }
  return n;
}

// The sample's implant on the sample CT's grid against an independent inside test at each CT
// sample (parity along an oblique ray, where the labelmap counts along the grid's k axis):
// Dice ≥ 0.99.
TEST(WriteLabelmap, TheSamplesImplantOnItsCtAgreesWithAnotherInsideTest) {
  const std::string ct = sample_case_path();
  if (!std::filesystem::exists(ct)) GTEST_SKIP() << "sample case not installed";
  const Volume grid = read_volume(ct);
  const AutoplanResult plan = autoplan(load_skull(ct).mesh, Landmarks{});
  ASSERT_TRUE(plan.planned()) << plan.message;
  const SkullMesh& implant = plan.implant.mesh;
  const std::vector<uint8_t> labels = labelmap_on_grid(implant, grid);
  const SurfaceLocator locator(implant);
  const auto [lo, hi] = mesh_bounds(implant);
  std::vector<uint8_t> inside(labels.size(), 0);
  for (int k = 0; k < grid.dims[2]; ++k)
    for (int j = 0; j < grid.dims[1]; ++j)
      for (int i = 0; i < grid.dims[0]; ++i) {
        const Eigen::Vector3d p = grid.world(Eigen::Vector3d(i, j, k));
        if ((p.array() < lo.array() - 1).any() || (p.array() > hi.array() + 1).any()) continue;
        inside[grid.index(i, j, k)] = crossings(locator, p, (hi - lo).norm() + 2) % 2;
      }
  EXPECT_GE(dice(labels, inside), 0.99);
}

// A segmentation from 3D Slicer as the skull: the segment named bone (or skull, cranium) is read
// as the mask; without one the file is refused, naming the segments.
TEST(WriteLabelmap, ASlicerSegmentationIsReadAsItsBoneSegment) {
  test::TempDir dir;
  const Eigen::Vector3d c(0, 0, 0);
  Volume v = test::make_ball_volume(c, 10.0, 40, 1.0, false);
  for (int k = 0; k < 40; ++k)
    for (int j = 0; j < 40; ++j)
      for (int i = 0; i < 40; ++i) {
        const double d = (v.world(Eigen::Vector3d(i, j, k)) - c).norm();
        v.data[v.index(i, j, k)] = d < 6 ? 1.0f : d < 10 ? 2.0f : (i < 3 ? 3.0f : 0.0f);
      }
  const std::string three =
      "Segment0_ID:=Segment_1\nSegment0_Name:=brain\nSegment0_LabelValue:=1\n"
      "Segment1_ID:=Segment_2\nSegment1_Name:=Skull bone\nSegment1_LabelValue:=2\n"
      "Segment2_ID:=Segment_3\nSegment2_Name:=table\nSegment2_LabelValue:=3\n";
  test::write_nrrd(v, dir.path("head.seg.nrrd"), true, "left-posterior-superior", three);
  const Volume bone = read_volume(dir.path("head.seg.nrrd"));
  EXPECT_EQ(bone.kind, VolumeKind::Mask);
  long long shell = 0, wrong = 0;
  for (size_t i = 0; i < v.size(); ++i) {
    shell += bone.data[i] == 1.0f;
    wrong += (bone.data[i] == 1.0f) != (v.data[i] == 2.0f);
  }
  EXPECT_EQ(wrong, 0);
  EXPECT_GT(shell, 1000);
  ASSERT_EQ(bone.warnings.size(), 1u);
  EXPECT_NE(bone.warnings[0].find("the segment 'Skull bone' is read as the skull"),
            std::string::npos);
  const LoadedSkull loaded = load_surface(dir.path("head.seg.nrrd"));
  EXPECT_GT(loaded.mesh.n_faces(), 500u);

  const std::string unnamed =
      "Segment0_ID:=Segment_1\nSegment0_Name:=left\nSegment0_LabelValue:=1\n"
      "Segment1_ID:=Segment_2\nSegment1_Name:=right\nSegment1_LabelValue:=2\n";
  test::write_nrrd(v, dir.path("two.seg.nrrd"), false, "left-posterior-superior", unnamed);
  try {
    read_volume(dir.path("two.seg.nrrd"));
    ADD_FAILURE();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("holds 2 segments ('left', 'right') and none is named "
                                         "bone, skull or cranium"),
              std::string::npos)
        << e.what();
  }
  test::write_nrrd(v, dir.path("empty.seg.nrrd"), false, "left-posterior-superior",
                   "Segment0_ID:=bone\nSegment0_LabelValue:=7\n");
  EXPECT_THROW(read_volume(dir.path("empty.seg.nrrd")), InputError);
}

}  // namespace
}  // namespace cranioplan
