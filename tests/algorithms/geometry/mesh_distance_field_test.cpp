#include "cranioplan/algorithms/geometry/mesh_distance_field.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "cranioplan/algorithms/geometry/surface_locator.h"
#include "cranioplan/algorithms/geometry/voxelize_mesh.h"
#include "cranioplan/algorithms/io/extract_bone_surface.h"
#include "support/synthetic.h"

namespace cranioplan {
namespace {

// A 20 mm cube: near its faces (away from edges) the field is the distance to the nearest face,
// positive inside; far from them ±10 mm; meshed at 0 it gives the cube back.
TEST(MeshDistanceField, NearTheSurfaceItIsTheSignedDistanceToIt) {
  const SkullMesh cube = build_mesh(test::box_soup({0, 0, 0}, {20, 20, 20}));
  const SurfaceLocator locator(cube);
  const VoxelGrid g = VoxelGrid::covering({0, 0, 0}, {20, 20, 20}, 0.5, 4);
  const std::vector<float> d = signed_distance_near_surface(locator, voxelize_mesh(cube, g), g);
  int exact = 0, far = 0;
  for (int k = 0; k < g.dims[2]; ++k)
    for (int j = 0; j < g.dims[1]; ++j)
      for (int i = 0; i < g.dims[0]; ++i) {
        const Eigen::Vector3d p = g.center(i, j, k);
        const float v = d[g.index(i, j, k)];
        if (std::abs(v) == 10.0f) {
          ++far;
          continue;
        }
        ++exact;
        // Inside: the distance to the nearest face; outside: to the nearest point of the cube.
        const bool inside = (p.array() > 0).all() && (p.array() < 20).all();
        const double truth =
            inside
                ? std::min({p.x(), p.y(), p.z(), 20 - p.x(), 20 - p.y(), 20 - p.z()})
                : -(p - p.cwiseMax(Eigen::Vector3d::Zero()).cwiseMin(Eigen::Vector3d::Constant(20)))
                       .norm();
        EXPECT_NEAR(v, truth, 1e-4) << p.transpose();
        EXPECT_LE(std::abs(truth), 2.7) << "only near the surface (3 voxels along each axis)";
      }
  EXPECT_GT(exact, 1000);
  EXPECT_GT(far, 1000);
  const ExtractBoneSurfaceResult s = surface_of_signed_distance(d, g);
  ASSERT_TRUE(s.usable()) << s.message;
  const auto [lo, hi] = mesh_bounds(s.mesh);
  EXPECT_NEAR(lo.x(), 0.0, 0.05);
  EXPECT_NEAR(hi.z(), 20.0, 0.05);
}

}  // namespace
}  // namespace cranioplan
