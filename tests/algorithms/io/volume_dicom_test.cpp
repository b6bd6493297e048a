#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>

#include "cranioplan/algorithms/io/extract_bone_surface.h"
#include "cranioplan/algorithms/io/read_volume.h"
#include "cranioplan/model/error.h"
#include "support/dicom_writer.h"
#include "support/synthetic.h"
#include "support/test_files.h"

namespace cranioplan {
namespace {

using test::oblique_ball_volume;

TEST(VolumeDicom, DicomSeriesFolderGivesWorldCoordinatesAndHounsfieldUnits) {
  test::TempDir dir;
  const Eigen::Vector3d center(-20, 35, 110);
  Volume v = test::make_ball_volume(center, 9.0, 30, 1.0, true);
  // Anisotropic and off-centre, like a real scan: 0.8 × 0.8 × 1.25 mm.
  v.directions = Eigen::Vector3d(0.8, 0.8, 1.25).asDiagonal();
  v.origin = center - v.directions * Eigen::Vector3d(12.0, 17.0, 14.5);
  for (int k = 0; k < 30; ++k)
    for (int j = 0; j < 30; ++j)
      for (int i = 0; i < 30; ++i)
        v.data[v.index(i, j, k)] =
            (v.world(Eigen::Vector3d(i, j, k)) - center).norm() <= 9.0 ? 1000.0f : -1000.0f;
  std::filesystem::create_directories(dir.path("series"));
  test::write_dicom_series(v, dir.path("series"));
  const Volume r = read_volume(dir.path("series"));
  EXPECT_EQ(r.dims, v.dims);
  EXPECT_NEAR(*std::max_element(r.data.begin(), r.data.end()), 1000.0f, 1e-3);
  EXPECT_NEAR(*std::min_element(r.data.begin(), r.data.end()), -1000.0f, 1e-3);
  EXPECT_LT((r.spacing() - v.spacing()).norm(), 1e-4);
  const auto surface = extract_bone_surface(r);
  ASSERT_TRUE(surface.usable());
  EXPECT_LT((vertex_centroid(surface.mesh) - center).norm(), 0.3);
  EXPECT_GT(signed_volume(surface.mesh), 0.0);
}

TEST(VolumeDicom, AFolderWithoutSlicesNamesWhatItHolds) {
  test::TempDir dir;
  std::filesystem::create_directories(dir.path("emptydir"));
  EXPECT_THROW(read_volume(dir.path("emptydir")), InputError);
  // A folder of other files: the reader's reason, and nothing of VTK's own on the terminal.
  std::filesystem::create_directories(dir.path("notes"));
  test::write_bytes(dir.path("notes/readme.txt"), "not a slice");
  testing::internal::CaptureStderr();
  try {
    read_volume(dir.path("notes"));
    ADD_FAILURE() << "a folder without slices was read";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("not a readable DICOM series"), std::string::npos)
        << e.what();
    EXPECT_NE(std::string(e.what()).find("readme.txt"), std::string::npos) << e.what();
  }
  EXPECT_EQ(testing::internal::GetCapturedStderr(), "");
}

TEST(VolumeDicom, TheSeriesOfAFolderAreListedWithTheirSize) {
  test::TempDir dir;
  Volume v = test::make_ball_volume(Eigen::Vector3d(0, 0, 50), 6.0, 20, 1.0, true);
  std::filesystem::create_directories(dir.path("series"));
  test::write_dicom_series(v, dir.path("series"));
  const std::vector<DicomSeries> series = list_dicom_series(dir.path("series"));
  ASSERT_EQ(series.size(), 1u);
  EXPECT_EQ(series[0].slices, 20);
  EXPECT_EQ(series[0].rows, 20);
  EXPECT_EQ(series[0].columns, 20);
  EXPECT_FALSE(series[0].uid.empty());
}

}  // namespace
}  // namespace cranioplan
