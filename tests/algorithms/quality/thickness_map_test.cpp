#include "cranioplan/algorithms/quality/thickness_map.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "cranioplan/algorithms/geometry/voxelize_mesh.h"
#include "cranioplan/algorithms/io/extract_bone_surface.h"
#include "support/synthetic.h"

namespace cranioplan {
namespace {

// A sheet of bone at z = 4 sampled every mm from −10 to 40 mm.
SkullMesh bone_sheet() {
  TriangleSoup s;
  const int n = 51;
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) s.vertices.emplace_back(i - 10.0, j - 10.0, 4.0);
  for (int j = 0; j + 1 < n; ++j)
    for (int i = 0; i + 1 < n; ++i) {
      const int a = j * n + i;
      s.triangles.push_back({a, a + 1, a + n + 1});
      s.triangles.push_back({a, a + n + 1, a + n});
    }
  return build_mesh(s);
}

// A 30 × 30 × 4 mm plate 3 mm above a sheet of bone: 4 mm over its faces; the bone under it
// reads a 3 mm gap, beside it the distance to the plate's edge, and farther than the reach none.
TEST(ThicknessMap, APlateIsItsThicknessAndTheBoneItsGap) {
  // The plate meshed as a CT import meshes a mask (0.5 mm voxels, its faces between voxel
  // centres): vertices all over its faces, its edges chamfered.
  const SkullMesh box = build_mesh(test::box_soup({0, 0, 7}, {30, 30, 11}));
  const VoxelGrid g = VoxelGrid::covering({-2.25, -2.25, 4.75}, {32.25, 32.25, 13.25}, 0.5);
  ExtractBoneSurfaceParams mask;
  mask.threshold = 0.5;
  const SkullMesh plate = extract_bone_surface(mask_volume(voxelize_mesh(box, g), g), mask).mesh;
  const SkullMesh bone = bone_sheet();
  ThicknessMapParams p;
  p.skull_reach_mm = 5.0;
  const ThicknessMap m = thickness_map(plate, &bone, p);
  ASSERT_EQ(m.implant_mm.size(), plate.n_vertices());
  ASSERT_EQ(m.skull_gap_mm.size(), bone.n_vertices());
  // On its faces, away from the chamfered edges: 4 mm to a quarter voxel of the map's grid.
  int on_faces = 0;
  for (auto vh : plate.vertices()) {
    const Eigen::Vector3d q = to_eigen(plate.point(vh));
    if (q.x() < 2 || q.x() > 28 || q.y() < 2 || q.y() > 28) continue;
    ++on_faces;
    EXPECT_NEAR(m.implant_mm[static_cast<size_t>(vh.idx())], 4.0, 0.07) << q.transpose();
  }
  EXPECT_GT(on_faces, 1000);
  EXPECT_NEAR(m.median_mm, 4.0, 0.07);
  // Under the plate a 3 mm gap; beside it the distance to its (chamfered) edge; beyond the
  // reach none.
  int under = 0, none = 0;
  for (auto vh : bone.vertices()) {
    const Eigen::Vector3d q = to_eigen(bone.point(vh));
    const double dx = std::max({0.0, -q.x(), q.x() - 30}), dy = std::max({0.0, -q.y(), q.y() - 30});
    const double box = std::sqrt(dx * dx + dy * dy + 9.0);  // to the box before meshing
    const float g = m.skull_gap_mm[static_cast<size_t>(vh.idx())];
    if (box > 5.5) {
      EXPECT_TRUE(std::isnan(g)) << q.transpose();
      ++none;
    } else if (q.x() >= 1 && q.x() <= 29 && q.y() >= 1 && q.y() <= 29) {
      EXPECT_NEAR(g, 3.0, 1e-3) << q.transpose();
      ++under;
    } else if (box < 4.5) {
      EXPECT_NEAR(g, box, 0.3) << q.transpose();
    }
  }
  EXPECT_EQ(under, 29 * 29);
  EXPECT_GT(none, 0);
}

// A curved shell (the thick synthetic head, outer and inner wall): the map reads its wall.
TEST(ThicknessMap, ACurvedShellReadsTheBonesThickness) {
  const SkullMesh head = test::make_thick_head(0.93, 1.0);
  const ThicknessMap m = thickness_map(head, nullptr);
  // The head's wall is 7 % of its radius: 5-6 mm, thinner where the head is narrower.
  EXPECT_GT(m.median_mm, 4.0);
  EXPECT_LT(m.median_mm, 7.0);
  EXPECT_TRUE(m.skull_gap_mm.empty());
}

}  // namespace
}  // namespace cranioplan
