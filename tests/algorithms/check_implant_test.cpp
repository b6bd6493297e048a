#include "cranioplan/algorithms/check_implant.h"

#include <gtest/gtest.h>

#include "cranioplan/algorithms/self_intersections.h"
#include "support/synthetic.h"

namespace cranioplan {
namespace {

SkullMesh box(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi) {
  return build_mesh(test::box_soup(lo, hi));
}

TEST(SelfIntersections, CrossingTrianglesAreCountedAndAClosedSurfaceHasNone) {
  TriangleSoup s;
  s.vertices = {{0, 0, 0}, {4, 0, 0}, {0, 4, 0}, {1, 1, -1}, {1, 1, 1}, {3, 3, 0.5}};
  s.triangles = {{0, 1, 2}, {3, 4, 5}};  // the second pierces the first
  EXPECT_EQ(count_self_intersections(build_mesh(s)), 1);
  EXPECT_EQ(count_self_intersections(test::make_symmetric_head(3)), 0);
}

TEST(CheckImplant, ThicknessVolumeAndReasonsOnKnownBoxes) {
  // A 30 × 30 × 4 mm plate: thickness 4 mm everywhere on its large faces.
  const QualityReport plate = check_implant(box({0, 0, 0}, {30, 30, 4}), nullptr);
  EXPECT_TRUE(plate.watertight);
  EXPECT_TRUE(plate.outward);
  EXPECT_NEAR(plate.volume_mm3, 3600.0, 1e-9);
  EXPECT_NEAR(plate.thickness_min_mm, 4.0, 1e-3);
  EXPECT_NEAR(plate.thickness_max_mm, 4.0, 1e-3);
  EXPECT_TRUE(plate.printable) << (plate.reasons.empty() ? "" : plate.reasons[0]);

  // Too thin to print, and overlapping a "skull" box by 30 × 30 × 0.2 mm = 180 mm³ (measured on
  // 0.25 mm voxels: within one voxel layer, 225 mm³).
  const SkullMesh thin = box({0, 0, 0}, {30, 30, 0.5});
  const SkullMesh skull = box({-10, -10, 0.3}, {40, 40, 10});
  const QualityReport q = check_implant(thin, &skull);
  EXPECT_FALSE(q.printable);
  EXPECT_NEAR(q.penetration_mm3, 180.0, 60.0);
  bool thin_reason = false, overlap_reason = false;
  for (const auto& r : q.reasons) {
    thin_reason |= r.find("thinnest part") != std::string::npos;
    overlap_reason |= r.find("overlap the skull") != std::string::npos;
  }
  EXPECT_TRUE(thin_reason);
  EXPECT_TRUE(overlap_reason);
}

}  // namespace
}  // namespace cranioplan
