#include "cranioplan/algorithms/implant/casting_mould.h"

#include <gtest/gtest.h>

#include <cmath>

#include "cranioplan/algorithms/geometry/surface_locator.h"
#include "cranioplan/algorithms/io/mesh_report.h"
#include "support/synthetic.h"

namespace cranioplan {
namespace {

// A 40 × 40 × 4 mm plate (z 7 to 11) meshed from a mask, as an implant is; the skull's inside
// lies below it.
SkullMesh plate() { return test::mask_meshed_box({0, 0, 7}, {40, 40, 11}); }
const Eigen::Vector3d kInside(20, 20, -60);

// The mould of a plate: two closed halves parting along its middle, the cavity within 0.2 mm of
// the plate everywhere, no undercut; the outer half has the pour channel and the vent through it
// (two tunnels) and sockets for the inner half's keys; the halves fill the block less the plate,
// the openings and the keys' clearance.
TEST(CastingMould, EachStatusHasItsWord) {
  EXPECT_STREQ(status_name(MouldResult::Status::Made), "made");
  EXPECT_STREQ(status_name(MouldResult::Status::Failed), "failed");
}

TEST(CastingMould, APlatesMouldHasItsCavityWithinAFifthOfAMillimetre) {
  const SkullMesh implant = plate();
  MouldParams p;
  const MouldResult r = make_casting_mould(implant, kInside, p);
  ASSERT_TRUE(r.usable()) << r.message;
  EXPECT_NEAR(std::abs(r.axis.z()), 1.0, 1e-6);
  EXPECT_GT(r.axis.z(), 0.0) << "the outer half away from the inside";
  EXPECT_LE(r.cavity_max_mm, 0.2);
  EXPECT_EQ(r.cavity_free_max_mm, r.cavity_max_mm) << "no folds";
  EXPECT_LT(r.undercut_mm2, 1.0);
  for (const SkullMesh* half : {&r.outer, &r.inner}) {
    const MeshReport rep = report_mesh(*half);
    EXPECT_TRUE(rep.watertight);
    EXPECT_EQ(rep.nonmanifold_edges, 0);
    EXPECT_EQ(rep.pieces, 1);
  }
  EXPECT_EQ(test::genus(r.outer), 2) << "pour channel and vent";
  EXPECT_EQ(test::genus(r.inner), 0);
  // The pour over the plate's top (z 11), the vent at least 20 mm from it.
  EXPECT_NEAR(r.pour.z(), 11.0, 0.3);
  EXPECT_GT((r.vent - r.pour).norm(), 20.0);
  // Volumes: the block (56 × 56 × 20 mm) less the plate, the channel and the vent (8 mm
  // long each) and the keys' clearance (four hemispheres of 2.7 against 2.5 mm).
  const double block = 56.0 * 56.0 * 20.0, plate_mm3 = report_mesh(implant).volume_mm3;
  const double openings = M_PI * (2.5 * 2.5 + 1.0) * 8.0;
  const double keys = 4.0 * 2.0 / 3.0 * M_PI * (std::pow(2.7, 3) - std::pow(2.5, 3));
  const double halves = report_mesh(r.outer).volume_mm3 + report_mesh(r.inner).volume_mm3;
  EXPECT_NEAR(halves, block - plate_mm3 - openings - keys, 0.01 * block);
  // The inner half's keys stand above the parting face into the outer half's sockets.
  const SurfaceLocator inner(r.inner);
  const auto on_key = inner.first_hit(Eigen::Vector3d(-4, -4, 30), Eigen::Vector3d(-4, -4, 0));
  ASSERT_TRUE(on_key.has_value());
  EXPECT_NEAR(on_key->point.z(), 9.0 + 2.5, 0.15) << "a key's top over the parting at z 9";
}

// A staple (two 40 × 40 × 2 mm flanges 4 mm apart, joined along one side) folds back over
// itself along any pull near its thin axis: the inner faces of the flanges are undercut whatever
// the parting, and the result says so (trapped), where a plate has none.
TEST(CastingMould, AShapeThatFoldsBackAlongThePullIsReportedTrapped) {
  const SkullMesh staple = test::mask_meshed_boxes(
      {{{0, 0, 7}, {40, 40, 9}}, {{0, 0, 13}, {40, 40, 15}}, {{0, 0, 7}, {4, 40, 15}}});
  const MouldResult r = make_casting_mould(staple, kInside, {});
  ASSERT_TRUE(r.usable()) << r.message;
  EXPECT_GT(r.trapped_mm2, 1000.0) << "at least one flange's inner face, 36 × 40 mm";
  EXPECT_GE(r.trapped_mm2, 0.9 * r.undercut_mm2);
  EXPECT_NE(r.message.find("folds back"), std::string::npos) << r.message;
  EXPECT_LE(r.cavity_free_max_mm, 0.2) << "outside the folds, the cavity is the staple";
  const MouldResult flat = make_casting_mould(plate(), kInside, {});
  EXPECT_EQ(flat.trapped_mm2, 0.0);
}

TEST(CastingMould, ParametersOutOfRangeAreNamed) {
  MouldParams p;
  EXPECT_EQ(mould_problem(p), "");
  p.wall_mm = 2.0;
  EXPECT_NE(mould_problem(p).find("wall must be 4 to 30 mm"), std::string::npos);
  p = MouldParams{};
  p.key_diameter_mm = 7.0;
  EXPECT_NE(mould_problem(p).find("for its keys"), std::string::npos);
  EXPECT_FALSE(make_casting_mould(SkullMesh{}, kInside).usable());
}

}  // namespace
}  // namespace cranioplan
