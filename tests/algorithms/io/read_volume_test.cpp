#include "cranioplan/algorithms/io/read_volume.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <filesystem>

#include "cranioplan/algorithms/io/extract_bone_surface.h"
#include "cranioplan/algorithms/io/load_skull.h"
#include "cranioplan/model/error.h"
#include "support/dicom_writer.h"
#include "support/synthetic.h"
#include "support/test_files.h"

namespace cranioplan {
namespace {

Eigen::Vector3d mesh_centroid(const SkullMesh& m) {
  Eigen::Vector3d c = Eigen::Vector3d::Zero();
  for (auto vh : m.vertices()) c += to_eigen(m.point(vh));
  return c / static_cast<double>(m.n_vertices());
}

// A ball mask on an oblique grid: the reader must put it where the grid's directions say.
Volume oblique_ball(const Eigen::Vector3d& center) {
  Volume v = test::make_ball_volume(Eigen::Vector3d::Zero(), 10.0, 32, 1.0, false);
  const Eigen::Matrix3d rot =
      Eigen::AngleAxisd(0.3, Eigen::Vector3d(1, 2, 0.5).normalized()).toRotationMatrix();
  v.directions = rot * Eigen::Vector3d(0.9, 1.0, 1.3).asDiagonal();
  // Centre index (15.5, 15.5, 15.5) must land on `center`.
  v.origin = center - v.directions * Eigen::Vector3d::Constant(15.5);
  // Refill: ball of radius 10 mm in world space.
  for (int k = 0; k < 32; ++k)
    for (int j = 0; j < 32; ++j)
      for (int i = 0; i < 32; ++i)
        v.data[v.index(i, j, k)] = (v.world(Eigen::Vector3d(i, j, k)) - center).norm() <= 10.0;
  return v;
}

TEST(ReadVolume, ObliqueNrrdRawAndGzipPlaceTheSurfaceInWorldCoordinates) {
  test::TempDir dir;
  const Eigen::Vector3d center(-120, 40, 17);
  const Volume v = oblique_ball(center);
  for (bool gz : {false, true}) {
    const std::string p = dir.path(gz ? "ball_gz.nrrd" : "ball_raw.nrrd");
    test::write_nrrd(v, p, gz);
    const Volume r = read_volume(p);
    EXPECT_EQ(r.dims, v.dims);
    EXPECT_EQ(r.kind, VolumeKind::Mask);
    EXPECT_LT((r.directions - v.directions).norm(), 1e-9);
    EXPECT_LT((r.origin - v.origin).norm(), 1e-9);
    const auto surface = extract_bone_surface(r);
    ASSERT_TRUE(surface.usable());
    EXPECT_LT((mesh_centroid(surface.mesh) - center).norm(), 0.5);
    EXPECT_GT(signed_volume(surface.mesh), 0.0);
    EXPECT_NEAR(signed_volume(surface.mesh), 4.0 / 3.0 * M_PI * 1000.0, 0.08 * 4188.8);
  }
}

// A CT loaded as a skull holds its surface once: OpenMesh meshes cannot be moved, so the
// import's copy used to stay in `surface` beside `mesh` for the skull's whole life (about 300 MB
// on a SkullFix mask).
TEST(ReadVolume, ALoadedVolumeHoldsItsSurfaceOnce) {
  test::TempDir dir;
  const std::string p = dir.path("ball.nrrd");
  test::write_nrrd(oblique_ball(Eigen::Vector3d(-120, 40, 17)), p, false);
  const LoadedSkull loaded = load_surface(p);
  EXPECT_EQ(loaded.source_kind, "volume");
  EXPECT_GT(loaded.mesh.n_faces(), 1000u);
  EXPECT_EQ(loaded.surface.mesh.n_vertices(), 0u);
  EXPECT_TRUE(loaded.surface.usable());
}

TEST(ReadVolume, NiftiSformGivesWorldCoordinates) {
  test::TempDir dir;
  const Eigen::Vector3d center(10, -20, 30);
  const Volume v = oblique_ball(center);
  test::write_nifti(v, dir.path("ball.nii"));
  const Volume r = read_volume(dir.path("ball.nii"));
  EXPECT_LT((r.directions - v.directions).norm(), 1e-5);
  EXPECT_LT((r.origin - v.origin).norm(), 1e-4);
  const auto surface = extract_bone_surface(r);
  EXPECT_LT((mesh_centroid(surface.mesh) - center).norm(), 0.5);
  test::write_bytes(dir.path("ball.nii.gz"), test::gzip(test::read_bytes(dir.path("ball.nii"))));
  EXPECT_EQ(read_volume(dir.path("ball.nii.gz")).data, r.data);
}

TEST(ReadVolume, HeaderThatDisagreesWithDataIsAnError) {
  test::TempDir dir;
  const Volume v = test::make_ball_volume(Eigen::Vector3d::Zero(), 5, 12, 1.0, false);
  test::write_nrrd(v, dir.path("ok.nrrd"), false);
  std::string bytes = test::read_bytes(dir.path("ok.nrrd"));
  test::write_bytes(dir.path("short.nrrd"), bytes.substr(0, bytes.size() - 100));
  try {
    read_volume(dir.path("short.nrrd"));
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("but the data holds only"), std::string::npos) << e.what();
  }
  test::write_bytes(dir.path("long.nrrd"), bytes + "extra");
  EXPECT_THROW(read_volume(dir.path("long.nrrd")), InputError);
  test::write_nrrd(v, dir.path("gz.nrrd"), true);
  std::string gz = test::read_bytes(dir.path("gz.nrrd"));
  test::write_bytes(dir.path("gzcut.nrrd"), gz.substr(0, gz.size() - 40));
  EXPECT_THROW(read_volume(dir.path("gzcut.nrrd")), InputError);
  test::write_bytes(dir.path("garbage.nii"), std::string(400, 'x'));
  EXPECT_THROW(read_volume(dir.path("garbage.nii")), InputError);
  test::write_bytes(dir.path("garbage.inv3"), std::string(400, 'x'));
  EXPECT_THROW(read_volume(dir.path("garbage.inv3")), InputError);
  test::write_bytes(dir.path("notgz.inv3"), test::gzip("not a tar archive at all"));
  EXPECT_THROW(read_volume(dir.path("notgz.inv3")), InputError);
  EXPECT_THROW(read_volume(dir.path("missing.nrrd")), InputError);
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

TEST(ReadVolume, SkullFixMaskHonoursObliqueDirections) {
  const std::string p = std::string(CRANIOPLAN_SKULLFIX_DIR) + "/000_implant.nrrd";
  if (!std::filesystem::exists(p)) GTEST_SKIP() << "SkullFix data not present";
  const Volume v = read_volume(p);
  EXPECT_EQ(v.kind, VolumeKind::Mask);
  EXPECT_EQ(v.dims[0], 512);
  EXPECT_NEAR(v.directions(2, 1), -0.0705786695, 1e-9);  // oblique: off-diagonal kept
  EXPECT_NEAR(v.origin.x(), -120.2, 1e-9);
}

}  // namespace
}  // namespace cranioplan

namespace cranioplan {
namespace {

TEST(ReadVolume, DicomSeriesFolderGivesWorldCoordinatesAndHounsfieldUnits) {
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
  EXPECT_LT((mesh_centroid(surface.mesh) - center).norm(), 0.3);
  EXPECT_GT(signed_volume(surface.mesh), 0.0);
}

}  // namespace
}  // namespace cranioplan
