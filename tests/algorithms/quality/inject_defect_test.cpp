#include "cranioplan/algorithms/quality/inject_defect.h"

#include <gtest/gtest.h>

#include "cranioplan/algorithms/geometry/voxelize_mesh.h"
#include "support/synthetic.h"

namespace cranioplan {
namespace {

TEST(InjectDefect, DefectiveAndImplantPartitionTheSkull) {
  const SkullMesh skull = test::make_thick_head();
  InjectDefectParams p;
  p.center = test::head_surface_point(Eigen::Vector3d(-0.6, 0.5, 0.6).normalized()) * 0.965;
  p.size_mm = 40;
  p.shape = InjectDefectParams::Shape::Cube;
  p.voxel_mm = 0.5;
  const InjectDefectResult r = inject_defect(skull, p);
  ASSERT_TRUE(r.usable()) << r.message;
  // On a common grid: union = skull, no overlap.
  const auto [lo, hi] = mesh_bounds(skull);
  const VoxelGrid g = VoxelGrid::covering(lo, hi, 0.5);
  const auto s = voxelize_mesh(skull, g), d = voxelize_mesh(r.defective, g),
             i = voxelize_mesh(r.implant, g);
  long long overlap = 0, mismatch = 0, bone = 0;
  for (size_t k = 0; k < s.size(); ++k) {
    overlap += d[k] && i[k];
    mismatch += (d[k] || i[k]) != (s[k] != 0);
    bone += s[k];
  }
  EXPECT_EQ(overlap, 0);
  EXPECT_LT(static_cast<double>(mismatch), 0.005 * static_cast<double>(bone));
  EXPECT_GT(r.removed_volume_mm3, 1000.0);

  p.center = {500, 0, 0};
  EXPECT_FALSE(inject_defect(skull, p).usable());
}

}  // namespace
}  // namespace cranioplan
