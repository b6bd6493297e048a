#include "cranioplan/model/plane.h"

#include <gtest/gtest.h>

namespace cranioplan {
namespace {

TEST(Plane, ReflectIsAnInvolutionAndFixesThePlane) {
  const Plane p = Plane::through({1, 2, 3}, {1, 1, 0});
  const Eigen::Vector3d x(4, -5, 6);
  EXPECT_LT((p.reflect(p.reflect(x)) - x).norm(), 1e-12);
  EXPECT_NEAR(p.signed_distance(p.reflect(x)), -p.signed_distance(x), 1e-12);
  const Eigen::Vector3d on = p.project(x);
  EXPECT_LT((p.reflect(on) - on).norm(), 1e-12);
  EXPECT_NEAR(p.angle_to_deg(p.flipped()), 0.0, 1e-9);
}

// Angles around an axis start from a direction given by the caller (anatomy, a marker), not
// from the coordinate axes; along the axis there is none, and any unit vector across will do.
TEST(Plane, UnitAcrossAnAxisDropsThePartAlongIt) {
  const Eigen::Vector3d axis = Eigen::Vector3d(1, 2, 2) / 3.0;
  const Eigen::Vector3d e = unit_across(Eigen::Vector3d(3, 0, 0), axis);
  EXPECT_NEAR(e.norm(), 1.0, 1e-12);
  EXPECT_NEAR(e.dot(axis), 0.0, 1e-12);
  EXPECT_NEAR(e.dot(Eigen::Vector3d(8, -2, -2).normalized()), 1.0, 1e-12);  // (3,0,0) − 1·(1,2,2)
  const Eigen::Vector3d any = unit_across(-2.0 * axis, axis);
  EXPECT_NEAR(any.norm(), 1.0, 1e-12);
  EXPECT_NEAR(any.dot(axis), 0.0, 1e-12);
}

TEST(Plane, ThroughAPointWithAnyNormalLengthIsTheSamePlane) {
  const Plane a = Plane::through({0, 0, 7}, {0, 0, 1});
  const Plane b = Plane::through({3, -4, 7}, {0, 0, 25});
  EXPECT_NEAR(b.normal.norm(), 1.0, 1e-12);
  EXPECT_NEAR(a.offset, 7.0, 1e-12);
  EXPECT_NEAR(b.offset, 7.0, 1e-12);
  EXPECT_NEAR(a.signed_distance({1, 1, 10}), 3.0, 1e-12);
  EXPECT_NEAR(a.flipped().signed_distance({1, 1, 10}), -3.0, 1e-12);
  // Reflection does not depend on the normal's sign.
  EXPECT_LT((a.reflect({1, 2, 10}) - a.flipped().reflect({1, 2, 10})).norm(), 1e-12);
  EXPECT_NEAR(a.angle_to_deg(Plane::through({}, {1, 0, 1})), 45.0, 1e-9);
  EXPECT_NEAR(a.angle_to_deg(Plane::through({}, {0, 0, -1})), 0.0, 1e-9);
}

}  // namespace
}  // namespace cranioplan
