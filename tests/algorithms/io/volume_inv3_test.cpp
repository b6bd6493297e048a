#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>

#include "cranioplan/algorithms/io/extract_bone_surface.h"
#include "cranioplan/algorithms/io/load_skull.h"
#include "cranioplan/algorithms/io/read_volume.h"
#include "cranioplan/model/error.h"
#include "support/synthetic.h"
#include "support/test_files.h"

namespace cranioplan {
namespace {

using test::oblique_ball_volume;

TEST(VolumeInv3, TheSampleProjectIsACtInHounsfieldUnits) {
  const std::string p = sample_case_path();
  if (!std::filesystem::exists(p)) GTEST_SKIP() << "sample case not installed";
  const Volume v = read_volume(p);
  EXPECT_EQ(v.kind, VolumeKind::CT);
  for (int a = 0; a < 3; ++a) EXPECT_GT(v.dims[a], 50) << a;
  const auto [lo, hi] = std::minmax_element(v.data.begin(), v.data.end());
  EXPECT_LT(*lo, -500.0f) << "air";
  EXPECT_GT(*hi, 1000.0f) << "bone";
  EXPECT_GT(v.spacing().minCoeff(), 0.1);
  EXPECT_LT(v.spacing().maxCoeff(), 5.0);
}

TEST(VolumeInv3, AFileThatIsNoProjectIsRefusedByName) {
  test::TempDir dir;
  for (const auto& [name, bytes] :
       {std::pair<std::string, std::string>{"garbage.inv3", std::string(400, 'x')},
        {"notgz.inv3", test::gzip("not a tar archive at all")}}) {
    test::write_bytes(dir.path(name), bytes);
    try {
      read_volume(dir.path(name));
      ADD_FAILURE() << name << " was read";
    } catch (const InputError& e) {
      EXPECT_EQ(std::string(e.what()).rfind(dir.path(name), 0), 0u) << e.what();
    }
  }
}

}  // namespace
}  // namespace cranioplan
