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

// A flap's shape: an elliptical cone from its apex, its angular half-length along `along` and
// half-width across, with bone kept on the other side of the midline, within the margin of it
// and below the floor.
TEST(InjectDefect, AFlapIsAnEllipticalConeOffTheMidlineAboveTheFloor) {
  FlapCut cut;
  cut.apex = Eigen::Vector3d::Zero();
  cut.axis = Eigen::Vector3d::UnitX();
  cut.along = Eigen::Vector3d::UnitY();
  cut.half_length_rad = 40.0 * M_PI / 180.0;
  cut.half_width_rad = 30.0 * M_PI / 180.0;
  auto at = [](double length_deg, double width_deg) {  // 90 mm out
    const double a = length_deg * M_PI / 180.0, b = width_deg * M_PI / 180.0;
    return Eigen::Vector3d(90.0, 90.0 * std::tan(a), 90.0 * std::tan(b));
  };
  EXPECT_TRUE(cut.contains(at(0, 0)));
  EXPECT_TRUE(cut.contains(at(39, 0)));
  EXPECT_FALSE(cut.contains(at(41, 0)));
  EXPECT_TRUE(cut.contains(at(0, 29)));
  EXPECT_FALSE(cut.contains(at(0, 31)));
  EXPECT_FALSE(cut.contains(at(30, 22))) << "outside the ellipse, inside its bounding box";
  EXPECT_FALSE(cut.contains(Eigen::Vector3d(-90, 0, 0))) << "behind the apex";

  // The midsagittal plane x = 20 (normal +x): one side, 15 mm off it.
  cut.midline = Plane{Eigen::Vector3d::UnitX(), 20.0};
  cut.midline_margin_mm = 15.0;
  cut.one_side = 1;
  EXPECT_TRUE(cut.contains(at(0, 0)));                          // 70 mm off the plane
  EXPECT_FALSE(cut.contains(Eigen::Vector3d(30.0, 0.0, 0.0)));  // 10 mm off it
  EXPECT_TRUE(cut.contains(Eigen::Vector3d(36.0, 0.0, 0.0)));   // 16 mm off it
  cut.one_side = -1;
  EXPECT_FALSE(cut.contains(at(0, 0))) << "the other side only";
  cut.one_side = 1;

  // The floor z = -10 (normal +z): bone below it kept.
  cut.floor = Plane{Eigen::Vector3d::UnitZ(), -10.0};
  EXPECT_TRUE(cut.contains(at(0, -6)));   // z = -9.5
  EXPECT_FALSE(cut.contains(at(0, -7)));  // z = -11.1

  InjectDefectParams p;
  p.shape = InjectDefectParams::Shape::Flap;
  p.flap = cut;
  EXPECT_EQ(in_defect(p, at(0, 0)), cut.contains(at(0, 0)));
  EXPECT_EQ(in_defect(p, at(0, -7)), cut.contains(at(0, -7)));
}

// A flap cut from the synthetic head: the bone removed lies within the cone, off the midline,
// and the head keeps the rest.
TEST(InjectDefect, AFlapIsCutOutOfTheSideOfTheHead) {
  const SkullMesh skull = test::make_thick_head();
  InjectDefectParams p;
  p.shape = InjectDefectParams::Shape::Flap;
  p.flap.axis = Eigen::Vector3d(1.0, 0.0, 0.3).normalized();
  p.flap.along = Eigen::Vector3d::UnitY();
  p.flap.half_length_rad = 0.7;
  p.flap.half_width_rad = 0.5;
  p.flap.midline = Plane{Eigen::Vector3d::UnitX(), 0.0};
  p.flap.midline_margin_mm = 15.0;
  p.flap.one_side = 1;
  p.voxel_mm = 0.5;
  const InjectDefectResult r = inject_defect(skull, p);
  ASSERT_TRUE(r.usable()) << r.message;
  EXPECT_GT(r.removed_volume_mm3, 20000.0) << "the size of a decompressive craniectomy's flap";
  for (auto vh : r.implant.vertices()) {
    const Eigen::Vector3d x(r.implant.point(vh)[0], r.implant.point(vh)[1], r.implant.point(vh)[2]);
    EXPECT_GT(x.x(), 15.0 - 0.5 - 1e-9) << "kept off the midline";
  }
}

}  // namespace
}  // namespace cranioplan
