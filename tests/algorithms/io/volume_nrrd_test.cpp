#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>

#include "cranioplan/algorithms/io/extract_bone_surface.h"
#include "cranioplan/algorithms/io/read_volume.h"
#include "cranioplan/model/error.h"
#include "support/synthetic.h"
#include "support/test_files.h"

namespace cranioplan {
namespace {

using test::oblique_ball_volume;

TEST(VolumeNrrd, ObliqueNrrdRawAndGzipPlaceTheSurfaceInWorldCoordinates) {
  test::TempDir dir;
  const Eigen::Vector3d center(-120, 40, 17);
  const Volume v = oblique_ball_volume(center);
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
    EXPECT_LT((vertex_centroid(surface.mesh) - center).norm(), 0.5);
    EXPECT_GT(signed_volume(surface.mesh), 0.0);
    EXPECT_NEAR(signed_volume(surface.mesh), 4.0 / 3.0 * M_PI * 1000.0, 0.08 * 4188.8);
  }
}

TEST(VolumeNrrd, SkullFixMaskHonoursObliqueDirections) {
  const std::string p = std::string(CRANIOPLAN_SKULLFIX_DIR) + "/000_implant.nrrd";
  if (!std::filesystem::exists(p)) GTEST_SKIP() << "SkullFix data not present";
  const Volume v = read_volume(p);
  EXPECT_EQ(v.kind, VolumeKind::Mask);
  EXPECT_EQ(v.dims[0], 512);
  EXPECT_NEAR(v.directions(2, 1), -0.0705786695, 1e-9);  // oblique: off-diagonal kept
  EXPECT_NEAR(v.origin.x(), -120.2, 1e-9);
}

TEST(VolumeNrrd, HeaderThatDisagreesWithDataIsAnError) {
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
}

// A gzipped NRRD whose header announces far more samples than its data could inflate to
// (deflate expands at most 1032 times) is refused with the count it announces and what the
// data holds, and nothing the size of the announced volume is allocated.
TEST(VolumeNrrd, AGzipHeaderAnnouncingMoreThanItsDataCanHoldIsRefused) {
  test::TempDir dir;
  const std::string data = test::gzip(std::string(4000, '\0'));
  test::write_bytes(dir.path("huge.nrrd"),
                    "NRRD0004\ntype: int32\ndimension: 3\nsizes: 90000 90000 90000\n"
                    "encoding: gzip\n\n" +
                        data);
  try {
    read_volume(dir.path("huge.nrrd"));
    FAIL();
  } catch (const InputError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("but the data holds only 4,000 bytes"), std::string::npos) << msg;
  }
}

}  // namespace
}  // namespace cranioplan
