#include "cranioplan/model/material.h"

#include <gtest/gtest.h>

#include <cmath>

namespace cranioplan {
namespace {

TEST(Material, ThePresetsAreUsableAndFoundByIdOrName) {
  ASSERT_EQ(material_presets().size(), 3u);
  for (const Material& m : material_presets()) {
    EXPECT_EQ(material_problem(m), "") << m.name;
    ASSERT_TRUE(material_preset(m.id));
    EXPECT_EQ(material_preset(m.id)->name, m.name);
  }
  EXPECT_EQ(material_preset("PEEK")->id, "peek");
  EXPECT_EQ(material_preset("Titanium Plate")->id, "titanium");
  EXPECT_FALSE(material_preset("bone cement"));
  // PEEK and PMMA follow the bone's thickness; the titanium plate is 1 mm, laid on the bone.
  EXPECT_TRUE(std::isnan(material_preset("peek")->thickness_mm));
  EXPECT_DOUBLE_EQ(material_preset("titanium")->thickness_mm, 1.0);
  EXPECT_GT(material_preset("titanium")->onlay_mm, 0.0);
  EXPECT_NEAR(material_preset("titanium")->density_g_cm3, 4.43, 1e-9);
}

TEST(Material, ValuesOutOfTheirRangesAreNamed) {
  Material m = *material_preset("peek");
  m.edge_clearance_mm = 3.5;
  EXPECT_NE(material_problem(m).find("edge clearance"), std::string::npos);
  m = *material_preset("peek");
  m.under_contour_mm = -0.1;
  EXPECT_NE(material_problem(m).find("under-contour"), std::string::npos);
  m = *material_preset("peek");
  m.thickness_mm = 1.0;  // below PEEK's 2 mm minimum
  EXPECT_NE(material_problem(m).find("minimum"), std::string::npos);
  m = *material_preset("titanium");
  m.edge_clearance_mm = 1.0;  // a plate on the bone has no gap at its edge
  EXPECT_NE(material_problem(m).find("on the bone"), std::string::npos);
  m = *material_preset("pmma");
  m.density_g_cm3 = std::nan("");
  EXPECT_NE(material_problem(m).find("density"), std::string::npos);
}

TEST(Material, TheClearanceAtAPointIsTheLargestThatHoldsIt) {
  const std::vector<ClearanceZone> zones = {{Eigen::Vector3d(10, 0, 0), 5.0, 3.0},
                                            {Eigen::Vector3d(20, 0, 0), 5.0, 2.0}};
  EXPECT_DOUBLE_EQ(clearance_at(Eigen::Vector3d(-10, 0, 0), 1.0, zones), 1.0);
  EXPECT_DOUBLE_EQ(clearance_at(Eigen::Vector3d(11, 0, 0), 1.0, zones), 3.0);
  EXPECT_DOUBLE_EQ(clearance_at(Eigen::Vector3d(11, 0, 0), 3.5, zones), 3.5);
  // Beyond its radius a zone blends into the clearance around it over kZoneBlendMm.
  EXPECT_DOUBLE_EQ(clearance_at(Eigen::Vector3d(10, -5 - 0.5 * kZoneBlendMm, 0), 1.0, zones), 2.0);
  EXPECT_DOUBLE_EQ(clearance_at(Eigen::Vector3d(10, -5 - kZoneBlendMm, 0), 1.0, zones), 1.0);
  EXPECT_DOUBLE_EQ(clearance_at(Eigen::Vector3d(24, 0, 0), 1.0, zones), 2.0);
  EXPECT_EQ(zone_problem(zones[0]), "");
  EXPECT_NE(zone_problem({Eigen::Vector3d::Zero(), 0.5, 1.0}).find("radius"), std::string::npos);
}

TEST(Material, ItsDescriptionNamesEveryValue) {
  EXPECT_EQ(describe(*material_preset("peek")),
            "PEEK (follows the bone, min 2.0 mm, clearance 1.0 mm, under-contour 0.0 mm, "
            "1.30 g/cm³)");
  EXPECT_NE(describe(*material_preset("titanium")).find("1.0 mm plate on the bone, 8 mm over"),
            std::string::npos);
}

}  // namespace
}  // namespace cranioplan
