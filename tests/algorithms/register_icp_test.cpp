#include "cranioplan/algorithms/register_icp.h"

#include <gtest/gtest.h>

#include "support/synthetic.h"

namespace cranioplan {
namespace {

void expect_transform_near(const RigidTransform& got, const RigidTransform& truth, double deg,
                           double mm, const SkullMesh& mesh) {
  EXPECT_LT((got.inverse() * truth).rotation_angle_deg(), deg);
  double worst = 0.0;
  for (auto vh : mesh.vertices()) {
    const Eigen::Vector3d p = to_eigen(mesh.point(vh));
    worst = std::max(worst, (got.apply(p) - truth.apply(p)).norm());
  }
  EXPECT_LT(worst, mm);
}

TEST(RegisterIcp, RecoversAKnownTransform) {
  const SkullMesh fixed = test::make_symmetric_head(5);
  const RigidTransform truth =
      RigidTransform::from_axis_angle({0.2, 0.5, 1.0}, 6.0, {3.0, -2.0, 4.0});
  const SkullMesh moving = test::transformed(fixed, truth.inverse());
  const RegisterResult r = register_icp(moving, fixed);
  ASSERT_TRUE(r.usable()) << r.message;
  EXPECT_EQ(r.status, RegisterResult::Status::Converged);
  expect_transform_near(r.transform, truth, 0.1, 0.1, moving);
  EXPECT_LT(r.rms_mm, 0.05);
}

TEST(RegisterIcp, TrimmedIcpIgnoresADefectInTheFixedMesh) {
  const SkullMesh full = test::make_symmetric_head(5);
  const SkullMesh fixed = test::cut_hole(full, {55, 30, 35}, 30.0);
  const RigidTransform truth =
      RigidTransform::from_axis_angle({1, 0.3, 0.1}, 4.0, {-2.0, 1.5, 2.5});
  const SkullMesh moving = test::transformed(full, truth.inverse());
  const RegisterResult r = register_icp(moving, fixed);
  ASSERT_TRUE(r.usable()) << r.message;
  expect_transform_near(r.transform, truth, 0.1, 0.1, moving);
}

// Where the file puts the skull does not matter: the same pair moved 400 mm from the origin
// takes the same steps (each turns about the pairs' centroid, not the origin, about which a
// turn and a shift nearly cancel), so it stops at the same place. Checked after every one of
// the first iterations, where the path shows.
TEST(RegisterIcp, TheSamePairFarFromTheOriginGivesTheSameMotion) {
  const SkullMesh full = test::make_symmetric_head(5);
  const SkullMesh fixed = test::cut_hole(full, {55, 30, 35}, 30.0);
  const RigidTransform truth =
      RigidTransform::from_axis_angle({1, 0.3, 0.1}, 4.0, {-2.0, 1.5, 2.5});
  const SkullMesh moving = test::transformed(full, truth.inverse());
  const RigidTransform shift = RigidTransform::from_axis_angle({0, 0, 1}, 0.0, {150, -300, 220});
  const SkullMesh moving_far = test::transformed(moving, shift);
  const SkullMesh fixed_far = test::transformed(fixed, shift);
  for (int iterations : {1, 2, 3, 60}) {
    RegisterParams params;
    params.max_iterations = iterations;
    const RegisterResult near = register_icp(moving, fixed, params);
    const RegisterResult far = register_icp(moving_far, fixed_far, params);
    ASSERT_TRUE(near.usable() && far.usable());
    EXPECT_EQ(far.iterations, near.iterations);
    // The far motion, brought back, is the near one.
    expect_transform_near(shift.inverse() * far.transform * shift, near.transform, 1e-4, 1e-4,
                          moving);
  }
}

TEST(RegisterIcp, RegionOfInterestRestrictsTheFit) {
  const SkullMesh fixed = test::make_symmetric_head(5);
  const RigidTransform truth = RigidTransform::from_axis_angle({0, 0, 1}, 2.0, {1.0, 1.0, -1.0});
  const SkullMesh moving = test::transformed(fixed, truth.inverse());
  RegisterParams p;
  RegionOfInterest roi;
  roi.center = {0, 80, 10};  // the face: nose ridge and forehead
  roi.radius = 60;
  p.roi = roi;
  const RegisterResult r = register_icp(moving, fixed, p);
  ASSERT_TRUE(r.usable()) << r.message;
  expect_transform_near(r.transform, truth, 0.1, 0.1, moving);

  roi.center = {1000, 0, 0};  // nowhere near the skull
  p.roi = roi;
  const RegisterResult none = register_icp(moving, fixed, p);
  EXPECT_FALSE(none.usable());
  EXPECT_NE(none.message.find("region of interest"), std::string::npos);
}

TEST(RegisterIcp, FarApartMeshesFailWithAStatus) {
  const SkullMesh fixed = test::make_symmetric_head(3);
  const SkullMesh moving =
      test::transformed(fixed, RigidTransform::from_axis_angle({0, 0, 1}, 0, {500, 0, 0}));
  const RegisterResult r = register_icp(moving, fixed);
  EXPECT_FALSE(r.usable());
}

}  // namespace
}  // namespace cranioplan
