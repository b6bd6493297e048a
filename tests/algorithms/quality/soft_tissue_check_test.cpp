#include "cranioplan/algorithms/quality/soft_tissue_check.h"

#include <gtest/gtest.h>

#include <cmath>

#include "cranioplan/algorithms/io/extract_bone_surface.h"
#include "support/synthetic.h"

namespace cranioplan {
namespace {

constexpr double kInner = 40.0, kOuter = 46.0;  // the skull's tables, mm from the centre
constexpr double kCapDeg = 35.0;                // the defect: within this angle of +z

bool in_cap(const Eigen::Vector3d& p) {
  return p.normalized().z() >= std::cos(kCapDeg * M_PI / 180.0);
}

// A head CT: bone between the tables except over the defect, cerebrospinal fluid (5 HU) from
// the brain's surface out to the inner table, brain (40 HU) inside `brain` — which bulges to
// `bulge` mm under the defect — and air outside. Over the defect a scalp (40 HU) from
// `scalp_from` to `scalp_to` mm, fluid between it and the brain; over the bone a scalp 6 mm
// thick.
Volume head_ct(double brain, double bulge, double scalp_from, double scalp_to) {
  Volume v = test::make_ball_volume(Eigen::Vector3d::Zero(), 1.0, 110, 1.0, true);
  for (int k = 0; k < 110; ++k)
    for (int j = 0; j < 110; ++j)
      for (int i = 0; i < 110; ++i) {
        const Eigen::Vector3d p = v.world(Eigen::Vector3d(i, j, k));
        const double r = p.norm();
        const bool cap = in_cap(p);
        float hu = -1000.0f;
        if (r < (cap ? bulge : brain))
          hu = 40.0f;
        else if (cap && r >= scalp_from && r < scalp_to)
          hu = 40.0f;
        else if (cap && r < scalp_from)
          hu = 5.0f;
        else if (r < kInner)
          hu = 5.0f;
        else if (r <= kOuter && !cap)
          hu = 1000.0f;
        else if (r <= kOuter + 6.0 && !cap)
          hu = 40.0f;
        v.data[v.index(i, j, k)] = hu;
      }
  return v;
}

// The implant: the missing cap of bone, between the tables.
SkullMesh cap_implant() {
  Volume mask = test::make_ball_volume(Eigen::Vector3d::Zero(), 1.0, 220, 0.5, false);
  for (int k = 0; k < 220; ++k)
    for (int j = 0; j < 220; ++j)
      for (int i = 0; i < 220; ++i) {
        const Eigen::Vector3d p = mask.world(Eigen::Vector3d(i, j, k));
        mask.data[mask.index(i, j, k)] = p.norm() >= kInner && p.norm() <= kOuter && in_cap(p);
      }
  return extract_bone_surface(mask).mesh;
}

TEST(SoftTissueCheck, BrainBulgingIntoTheDefectIsMeasured) {
  static const SkullMesh implant = cap_implant();
  // The brain bulges 2 mm past the inner table, the scalp on it reaching 5 mm past the outer
  // table: the implant's inner 2 mm lie in brain, its inner half's last mm in scalp, all under
  // a skin that stands over the implant.
  const SoftTissueCheck bulging =
      check_soft_tissue(implant, head_ct(39.0, 42.0, 42.0, 51.0), Eigen::Vector3d::Zero());
  ASSERT_TRUE(bulging.checked);
  const double expected = 2 * M_PI * (1 - std::cos(kCapDeg * M_PI / 180.0)) *
                          (std::pow(43.0, 3) - std::pow(kInner, 3)) / 3.0;  // 5,810 mm³
  EXPECT_NEAR(bulging.intrusion_mm3, expected, 0.15 * expected);
  EXPECT_EQ(bulging.sunken_scalp_mm3, 0.0);
  EXPECT_NEAR(bulging.scalp_mm, 6.0, 0.6) << "the scalp over the bone around the defect";
  EXPECT_NEAR(bulging.intrusion_reach_mm, 3.0, 0.8) << "brain 2 mm, scalp 1 mm into the implant";
  EXPECT_TRUE(bulging.finding);
  EXPECT_EQ(bulging.closest_mm, 0.0);
  EXPECT_FALSE(bulging.intrusion.empty());
  for (const Eigen::Vector3d& p : bulging.intrusion) {
    EXPECT_LT(p.norm(), 43.5);
    EXPECT_GT(p.norm(), kInner - 0.5);
  }
  EXPECT_NE(bulging.message.find("brain or dura reaching up to"), std::string::npos);

  // Years after a craniectomy the scalp has sunk into the defect: brain 3 mm under the inner
  // table, the scalp (4 mm) on it, its skin 1 mm above the inner table — inside the implant.
  // The tissue in the implant's place lies within a scalp's thickness (6 mm, as over the bone
  // around) under the skin: the scalp the implant will lift, no finding.
  const SoftTissueCheck sunken =
      check_soft_tissue(implant, head_ct(39.0, 37.0, 37.0, 41.0), Eigen::Vector3d::Zero());
  EXPECT_EQ(sunken.intrusion_mm3, 0.0) << sunken.message;
  EXPECT_FALSE(sunken.finding);
  EXPECT_TRUE(sunken.intrusion.empty());
  const double scalp_mm3 = 2 * M_PI * (1 - std::cos(kCapDeg * M_PI / 180.0)) *
                           (std::pow(41.0, 3) - std::pow(kInner, 3)) / 3.0;  // 946 mm³
  EXPECT_NEAR(sunken.sunken_scalp_mm3, scalp_mm3, 0.35 * scalp_mm3);
  EXPECT_FALSE(std::isfinite(sunken.closest_mm) && sunken.closest_mm < 0.5) << sunken.message;
  EXPECT_NE(sunken.message.find("scalp sunk into the defect"), std::string::npos) << sunken.message;

  // A brain 1 mm under the inner table, fluid between it and the scalp over the outer table:
  // nothing intrudes, and the closest approach is that millimetre.
  const SoftTissueCheck clear =
      check_soft_tissue(implant, head_ct(39.0, 39.0, 46.0, 52.0), Eigen::Vector3d::Zero());
  EXPECT_EQ(clear.intrusion_mm3, 0.0);
  EXPECT_NEAR(clear.closest_mm, 1.0, 0.5);
  EXPECT_NE(clear.message.find("soft tissue lies"), std::string::npos) << clear.message;

  // Scalp-like tissue outside the implant is not under it: a CT whose only tissue lies above
  // the outer table reports none under the implant.
  Volume scalp = head_ct(0.0, 0.0, 0.0, 0.0);
  for (size_t n = 0; n < scalp.size(); ++n) {
    const Eigen::Vector3d p = scalp.world(Eigen::Vector3d(static_cast<double>(n % 110),
                                                          static_cast<double>(n / 110 % 110),
                                                          static_cast<double>(n / 12100)));
    if (p.norm() > kOuter && p.norm() < kOuter + 4) scalp.data[n] = 40.0f;
  }
  const SoftTissueCheck outside = check_soft_tissue(implant, scalp, Eigen::Vector3d::Zero());
  EXPECT_EQ(outside.intrusion_mm3, 0.0);
  EXPECT_FALSE(std::isfinite(outside.closest_mm)) << outside.message;

  // A mask has no tissue to check.
  Volume mask = head_ct(39.0, 39.0, 0.0, 0.0);
  mask.kind = VolumeKind::Mask;
  EXPECT_FALSE(check_soft_tissue(implant, mask, Eigen::Vector3d::Zero()).checked);
}

}  // namespace
}  // namespace cranioplan
