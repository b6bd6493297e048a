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

TEST(VolumeNifti, NiftiSformGivesWorldCoordinates) {
  test::TempDir dir;
  const Eigen::Vector3d center(10, -20, 30);
  const Volume v = oblique_ball_volume(center);
  test::write_nifti(v, dir.path("ball.nii"));
  const Volume r = read_volume(dir.path("ball.nii"));
  EXPECT_LT((r.directions - v.directions).norm(), 1e-5);
  EXPECT_LT((r.origin - v.origin).norm(), 1e-4);
  const auto surface = extract_bone_surface(r);
  EXPECT_LT((vertex_centroid(surface.mesh) - center).norm(), 0.5);
  test::write_bytes(dir.path("ball.nii.gz"), test::gzip(test::read_bytes(dir.path("ball.nii"))));
  EXPECT_EQ(read_volume(dir.path("ball.nii.gz")).data, r.data);
}

TEST(VolumeNifti, AFileThatIsNoNiftiIsRefused) {
  test::TempDir dir;
  test::write_bytes(dir.path("garbage.nii"), std::string(400, 'x'));
  EXPECT_THROW(read_volume(dir.path("garbage.nii")), InputError);
  test::write_bytes(dir.path("short.nii"), std::string(100, '\0'));
  EXPECT_THROW(read_volume(dir.path("short.nii")), InputError);
}

}  // namespace
}  // namespace cranioplan
