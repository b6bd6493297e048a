#include "cranioplan/algorithms/alignment/register_icp.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include "cranioplan/algorithms/alignment/fit_sagittal_plane.h"
#include "cranioplan/algorithms/alignment/mirror_mesh.h"
#include "cranioplan/algorithms/geometry/point_index.h"
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

// The head with a hole (fixed) and the intact head moved away from it by `truth` (moving).
struct HolePair {
  SkullMesh fixed, moving;
  RigidTransform truth = RigidTransform::from_axis_angle({1, 0.3, 0.1}, 4.0, {-2.0, 1.5, 2.5});
};
const HolePair& hole_pair() {
  static const HolePair pair = [] {
    HolePair p;
    const SkullMesh full = test::make_symmetric_head(5);
    p.fixed = test::cut_hole(full, {55, 30, 35}, 30.0);
    p.moving = test::transformed(full, p.truth.inverse());
    return p;
  }();
  return pair;
}

TEST(RegisterIcp, TrimmedIcpIgnoresADefectInTheFixedMesh) {
  const auto& [fixed, moving, truth] = hole_pair();
  const RegisterResult r = register_icp(moving, fixed);
  ASSERT_TRUE(r.usable()) << r.message;
  expect_transform_near(r.transform, truth, 0.1, 0.1, moving);
}

// Where the file puts the skull does not matter: the same pair moved 400 mm from the origin
// takes the same steps (each turns about the pairs' centroid, not the origin, about which a
// turn and a shift nearly cancel), so it stops at the same place. Checked after every one of
// the first iterations, where the path shows.
TEST(RegisterIcp, TheSamePairFarFromTheOriginGivesTheSameMotion) {
  const auto& [fixed, moving, truth] = hole_pair();
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

// The mirror registered without building it (the skull onto itself from the reflection) takes
// the same path as the mirrored mesh registered onto the skull: the same samples (vertex i of
// the mirror is the image of vertex i), the same normals, the same steps. Asymmetric by a hole
// and a plane 3° and 2 mm off, so the registration has somewhere to go, globally and in a
// region.
TEST(RegisterIcp, MirrorRegisteredWithoutItsMeshIsTheMirrorMeshRegistered) {
  const SkullMesh& skull = hole_pair().fixed;
  const Plane plane = Plane::through(
      {2.0, 0.0, 0.0},
      Eigen::AngleAxisd(3.0 * M_PI / 180.0, Eigen::Vector3d(0.2, 0.3, 1.0).normalized()) *
          Eigen::Vector3d::UnitX());
  const SkullMesh mirror = mirror_mesh(skull, plane);
  RegisterParams global;
  RegisterParams local;
  local.roi = RegionOfInterest{};
  local.roi->center = Eigen::Vector3d(-40, 20, 40);
  local.roi->radius = 45.0;
  for (const RegisterParams& params : {global, local}) {
    const RegisterResult with_mesh = register_icp(mirror, skull, params);
    const RegisterResult without = register_mirror(skull, plane, params);
    ASSERT_TRUE(with_mesh.usable() && without.usable()) << without.message;
    EXPECT_GT(with_mesh.transform.rotation_angle_deg(), 1.0) << "nothing to register";
    EXPECT_EQ(without.iterations, with_mesh.iterations);
    expect_transform_near(without.transform, with_mesh.transform, 1e-4, 1e-4, mirror);
    EXPECT_NEAR(without.rms_mm, with_mesh.rms_mm, 1e-9);
  }
}

// The skull's vertex cloud made once and shared gives the plane and the registrations exactly
// as each stage making its own; an empty cloud is no error.
TEST(RegisterIcp, ASharedVertexCloudGivesTheSameResults) {
  const SkullMesh& skull = hole_pair().fixed;
  const VertexCloud cloud(skull);
  const PlaneFit own_fit = fit_sagittal_plane(skull, Landmarks{});
  const PlaneFit shared_fit = fit_sagittal_plane(skull, Landmarks{}, PlaneFitParams{}, &cloud);
  ASSERT_TRUE(own_fit.usable());
  EXPECT_EQ(shared_fit.plane.normal, own_fit.plane.normal);
  EXPECT_EQ(shared_fit.plane.offset, own_fit.plane.offset);
  RegisterParams local;
  local.roi = RegionOfInterest{};
  local.roi->center = Eigen::Vector3d(-40, 20, 40);
  local.roi->radius = 45.0;
  for (const RegisterParams& params : {RegisterParams{}, local}) {
    const RegisterResult own = register_mirror(skull, own_fit.plane, params);
    const RegisterResult shared = register_mirror(skull, own_fit.plane, params, &cloud);
    ASSERT_TRUE(own.usable()) << own.message;
    EXPECT_EQ(shared.transform.rotation, own.transform.rotation);
    EXPECT_EQ(shared.transform.translation, own.transform.translation);
    EXPECT_EQ(shared.iterations, own.iterations);
  }
  const VertexCloud empty{SkullMesh()};
  EXPECT_EQ(empty.index.size(), 0u);
  EXPECT_TRUE(empty.index.within_radius(Eigen::Vector3d::Zero(), 5.0).empty());
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
