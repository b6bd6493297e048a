#include "cranioplan/model/rigid_transform.h"

#include <gtest/gtest.h>

#include <Eigen/LU>

namespace cranioplan {
namespace {

TEST(RigidTransform, InverseAndComposition) {
  const RigidTransform t = RigidTransform::from_axis_angle({1, 2, 3}, 30, {4, 5, 6});
  const Eigen::Vector3d x(1, -1, 2);
  EXPECT_LT(((t.inverse() * t).apply(x) - x).norm(), 1e-12);
  EXPECT_NEAR(t.rotation_angle_deg(), 30.0, 1e-9);
}

// (a ∘ b)(x) = a(b(x)): the order the registration composes its steps in.
TEST(RigidTransform, CompositionAppliesTheRightOperandFirst) {
  const RigidTransform a = RigidTransform::from_axis_angle({0, 0, 1}, 90, {1, 0, 0});
  const RigidTransform b = RigidTransform::from_axis_angle({0, 0, 1}, 0, {0, 2, 0});
  const Eigen::Vector3d x(1, 0, 0);
  EXPECT_LT(((a * b).apply(x) - a.apply(b.apply(x))).norm(), 1e-12);
  // b moves (1,0,0) to (1,2,0); a turns it to (−2,1,0) and shifts it to (−1,1,0).
  EXPECT_LT(((a * b).apply(x) - Eigen::Vector3d(-1, 1, 0)).norm(), 1e-12);
}

TEST(RigidTransform, DirectionsTurnButDoNotMove) {
  const RigidTransform t = RigidTransform::from_axis_angle({0, 0, 5}, 90, {10, 20, 30});
  EXPECT_LT((t.apply_direction({1, 0, 0}) - Eigen::Vector3d(0, 1, 0)).norm(), 1e-12);
  EXPECT_NEAR(t.rotation.determinant(), 1.0, 1e-12) << "a rotation, not a reflection";
  EXPECT_NEAR(RigidTransform::from_axis_angle({1, 1, 0}, 180, {}).rotation_angle_deg(), 180.0,
              1e-6);
  EXPECT_NEAR(RigidTransform{}.rotation_angle_deg(), 0.0, 1e-12);
}

}  // namespace
}  // namespace cranioplan
