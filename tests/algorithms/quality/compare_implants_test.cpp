#include "cranioplan/algorithms/quality/compare_implants.h"

#include <gtest/gtest.h>

#include "cranioplan/algorithms/geometry/voxelize_mesh.h"
#include "support/synthetic.h"

namespace cranioplan {
namespace {

SkullMesh sphere(double radius, const Eigen::Vector3d& c = Eigen::Vector3d::Zero()) {
  SkullMesh m = test::make_symmetric_head(4);  // any closed mesh, replaced by a sphere below
  TriangleSoup s = to_soup(m);
  for (auto& p : s.vertices) p = c + radius * p.normalized();
  return build_mesh(s);
}

TEST(CompareImplants, IdenticalGiveDiceOneAndZeroDistance) {
  const SkullMesh a = sphere(10);
  const CompareResult r = compare_implants(a, a);
  EXPECT_DOUBLE_EQ(r.dice, 1.0);
  EXPECT_DOUBLE_EQ(r.hausdorff_mm, 0.0);
  EXPECT_DOUBLE_EQ(r.hd95_mm, 0.0);
}

TEST(CompareImplants, DisjointGiveDiceZero) {
  const CompareResult r = compare_implants(sphere(5), sphere(5, {30, 0, 0}));
  EXPECT_DOUBLE_EQ(r.dice, 0.0);
  // The far side of one sphere is 30 mm from the nearest point of the other.
  EXPECT_NEAR(r.hausdorff_mm, 30.0, 0.6);
}

TEST(CompareImplants, ConcentricSpheresGiveTheirRadiusDifference) {
  const CompareResult r =
      compare_implants(sphere(20), sphere(25), nullptr, CompareParams{0.25, 10});
  EXPECT_NEAR(r.hausdorff_mm, 5.0, 0.3);
  // Dice of nested balls: 2·r1³ / (r1³ + r2³)
  EXPECT_NEAR(r.dice, 2.0 * 8000.0 / (8000.0 + 15625.0), 0.02);
  EXPECT_NEAR(r.volume_b_mm3, 4.0 / 3.0 * M_PI * 15625.0, 0.02 * 65450.0);
}

TEST(CompareImplants, BoundaryDiceOnlyCountsVoxelsNearTheSkull) {
  const SkullMesh a = sphere(20), b = sphere(22);
  const SkullMesh skull = sphere(5, {0, 0, 40});  // touches nothing: nothing within 10 mm
  const CompareResult r = compare_implants(a, b, &skull);
  EXPECT_DOUBLE_EQ(r.boundary_dice, 1.0);  // both empty near the skull: perfect agreement
  const SkullMesh near_skull = sphere(5, {0, 0, 28});
  const CompareResult s = compare_implants(a, b, &near_skull);
  EXPECT_LT(s.boundary_dice, r.dice + 1e-9);
}

}  // namespace
}  // namespace cranioplan
