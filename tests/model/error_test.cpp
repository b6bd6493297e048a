#include "cranioplan/model/error.h"

#include <gtest/gtest.h>

namespace cranioplan {
namespace {

TEST(Error, InputErrorNamesFileFirstAndCountsReadably) {
  const InputError e("skull.stl", "file ends after 1,203 of 40,000 triangles");
  EXPECT_STREQ(e.what(), "skull.stl: file ends after 1,203 of 40,000 triangles");
  EXPECT_EQ(format_count(40000), "40,000");
  EXPECT_EQ(format_count(-1234567), "-1,234,567");
  EXPECT_EQ(format_count(999), "999");
}

TEST(Error, AnInputErrorKeepsItsPartsAndIsCaughtAsAnError) {
  try {
    throw InputError("/data/case 7/skull.stl", "no triangles");
  } catch (const Error& e) {
    const auto* input = dynamic_cast<const InputError*>(&e);
    ASSERT_NE(input, nullptr);
    EXPECT_EQ(input->path(), "/data/case 7/skull.stl");
    EXPECT_EQ(input->problem(), "no triangles");
    EXPECT_STREQ(e.what(), "/data/case 7/skull.stl: no triangles");
  }
  EXPECT_EQ(format_count(0), "0");
  EXPECT_EQ(format_count(1000), "1,000");
}

}  // namespace
}  // namespace cranioplan
