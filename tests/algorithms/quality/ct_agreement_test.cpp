#include "cranioplan/algorithms/quality/ct_agreement.h"

#include <gtest/gtest.h>

#include "support/synthetic.h"

namespace cranioplan {
namespace {

// A ball "skull" and its CT: the CT's own bone surface lies on it; the same CT 15 mm off (or a
// ball of another size, another patient) does not.
TEST(CtAgreement, TheSkullsOwnCtAgreesAndAnotherDoesNot) {
  const Volume ct = test::make_ball_volume(Eigen::Vector3d(10, -5, 40), 30.0, 40, 2.0, true);
  const SkullMesh skull = extract_bone_surface(ct).mesh;
  const CtAgreement own = ct_agreement(skull, ct);
  EXPECT_TRUE(own.agrees) << own.message;
  EXPECT_LT(own.median_mm, 0.05);
  EXPECT_NE(own.message.find("from the CT's bone surface"), std::string::npos);

  Volume moved = ct;
  moved.origin += Eigen::Vector3d(15, 0, 0);
  const CtAgreement off = ct_agreement(skull, moved);
  EXPECT_FALSE(off.agrees);
  EXPECT_GT(off.p90_mm, 5.0);
  EXPECT_NE(off.message.find("not this skull's CT, or not in its frame"), std::string::npos)
      << off.message;

  const Volume other = test::make_ball_volume(Eigen::Vector3d(10, -5, 40), 26.0, 40, 2.0, true);
  EXPECT_FALSE(ct_agreement(skull, other).agrees) << "4 mm smaller everywhere";

  // A threshold above every sample finds no bone at all.
  CtAgreementParams high;
  high.surface.threshold = 5000;
  const CtAgreement none = ct_agreement(skull, ct, high);
  EXPECT_FALSE(none.agrees);
  EXPECT_EQ(none.message, "the CT has no bone surface at the plan's threshold");
}

}  // namespace
}  // namespace cranioplan
