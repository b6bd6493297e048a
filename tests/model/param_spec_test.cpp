#include "cranioplan/model/param_spec.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace cranioplan {
namespace {

TEST(ParamSpec, ProblemSaysWhoseWhatTheRangeAndTheValue) {
  const ParamSpec diameter = length_mm("diameter_mm", "diameter", 1, 6);
  EXPECT_TRUE(diameter.ranged());
  EXPECT_TRUE(diameter.allows(1.0));
  EXPECT_TRUE(diameter.allows(6.0));
  EXPECT_FALSE(diameter.allows(6.01));
  EXPECT_FALSE(diameter.allows(std::numeric_limits<double>::quiet_NaN()));
  EXPECT_FALSE(diameter.allows(std::numeric_limits<double>::infinity()));
  EXPECT_EQ(diameter.problem("the holes'", 8.0), "the holes' diameter must be 1 to 6 mm (8 given)");
  // A bound set by another parameter, in the same words.
  EXPECT_EQ(diameter.problem("the holes'", 0.5, 2.5, 6),
            "the holes' diameter must be 2.5 to 6 mm (0.5 given)");
  // Counts have no unit; large bounds are written as a person reads them.
  EXPECT_EQ(number("max_voxels", "number of grid voxels", 1e5, 5e7).problem("the tabs'", 10),
            "the tabs' number of grid voxels must be 100,000 to 50,000,000 (10 given)");
}

TEST(ParamSpec, UnsetIsAllowedOnlyWhereTheValueIsDerived) {
  const ParamSpec width = length_mm("width_mm", "width", 3, 15);
  EXPECT_FALSE(width.allows(std::nan("")));
  EXPECT_TRUE(width.unset_derived().allows(std::nan("")));
  EXPECT_FALSE(width.unset_derived().allows(2.0));
  EXPECT_FALSE(field("positions").ranged());
}

TEST(ParamSpec, ZeroCanMeanNoneBelowTheRange) {
  const ParamSpec onlay = length_mm("onlay_mm", "onlay's overlap", 3, 20).zero_for_none();
  EXPECT_TRUE(onlay.allows(0.0));
  EXPECT_FALSE(onlay.allows(2.0));
  EXPECT_FALSE(onlay.allows(-1.0));
  EXPECT_TRUE(onlay.allows(3.0));
  EXPECT_EQ(onlay.problem("the", 2.0), "the onlay's overlap must be 0, or 3 to 20 mm (2 given)");
  EXPECT_EQ(onlay.range_text(), "0, or 3 to 20 mm");
}

// A Params struct of the test's own, declared as the product's are.
struct Toy {
  double length = 5.0;
  int count = 2;
  bool flag = false;
};
template <class Visit>
void for_each_field(Visit&& visit, Toy& p) {
  visit(length_mm("length_mm", "length", 1, 10).with_option("length", "how long"), p.length);
  visit(number("count", "count", 0, 3), p.count);
  visit(field("flag"), p.flag);
}

TEST(ParamSpec, TheFirstFieldOutOfItsRangeIsNamed) {
  Toy t;
  EXPECT_EQ(range_problems("the toy's", t), "");
  t.count = 4;
  EXPECT_EQ(range_problems("the toy's", t), "the toy's count must be 0 to 3 (4 given)");
  t.length = 0.5;  // declared first: named first
  EXPECT_EQ(range_problems("the toy's", t), "the toy's length must be 1 to 10 mm (0.5 given)");
  const ParamSpec s = spec_of<Toy>("length_mm");
  EXPECT_STREQ(s.option, "length");
  EXPECT_STREQ(s.help, "how long");
}

}  // namespace
}  // namespace cranioplan
