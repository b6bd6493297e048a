// The command-line contract: exit codes, --json, and messages for bad input.
#include <gtest/gtest.h>

#include "cranioplan/algorithms/write_mesh.h"
#include "cranioplan/sessions/plan_files.h"
#include "support/synthetic.h"
#include "support/test_files.h"

namespace cranioplan {
namespace {

const std::string kCli = CRANIOPLAN_CLI;

TEST(Cli, InfoPlaneMirrorRegisterOnASyntheticHead) {
  test::TempDir dir;
  const SkullMesh head = test::make_symmetric_head(4);
  write_mesh(head, dir.path("head.stl"));
  std::string out;
  ASSERT_EQ(test::run_command(kCli + " info " + dir.path("head.stl") + " --json", &out), 0);
  const Json info = Json::parse(out);
  EXPECT_TRUE(info["watertight"].get<bool>());
  EXPECT_EQ(info["triangles"].get<long long>(), static_cast<long long>(head.n_faces()));

  ASSERT_EQ(test::run_command(kCli + " plane " + dir.path("head.stl") + " --json -o " + dir.path("plane.json"), &out), 0);
  const Json plane = Json::parse(out);
  for (const char* key : {"normal", "offset_mm", "symmetry_rms_mm", "inlier_fraction", "iterations", "status"})
    EXPECT_TRUE(plane.contains(key)) << key;
  EXPECT_NEAR(std::abs(plane["normal"][0].get<double>()), 1.0, 1e-4);

  ASSERT_EQ(test::run_command(kCli + " mirror " + dir.path("head.stl") + " --plane " + dir.path("plane.json") + " -o " + dir.path("m.ply"), &out), 0);
  ASSERT_EQ(test::run_command(kCli + " register " + dir.path("m.ply") + " " + dir.path("head.stl") + " --json -o " + dir.path("r.stl") + " --roi-center 0,80,0 --roi-radius 80", &out), 0);
  const Json reg = Json::parse(out);
  EXPECT_EQ(reg["rotation"].size(), 3u);
  EXPECT_LT(reg["rms_mm"].get<double>(), 0.1);
}

TEST(Cli, ExitCodesForUsageAndBadInput) {
  test::TempDir dir;
  EXPECT_EQ(test::run_command(kCli), 2);
  EXPECT_EQ(test::run_command(kCli + " frobnicate"), 2);
  EXPECT_EQ(test::run_command(kCli + " info"), 2);
  EXPECT_EQ(test::run_command(kCli + " info --help"), 0);
  EXPECT_EQ(test::run_command(kCli + " info " + dir.path("missing.stl")), 3);
  test::write_bytes(dir.path("empty.stl"), "");
  std::string out;
  EXPECT_EQ(test::run_command(kCli + " info --json " + dir.path("empty.stl"), &out), 3);
  const Json err = Json::parse(out);
  EXPECT_NE(err["error"].get<std::string>().find("empty.stl: file is empty"), std::string::npos);
  test::write_bytes(dir.path("bad.json"), "nope");
  write_mesh(test::make_symmetric_head(2), dir.path("h.stl"));
  EXPECT_EQ(test::run_command(kCli + " plane " + dir.path("h.stl") + " --landmarks " + dir.path("bad.json")), 3);
  EXPECT_EQ(test::run_command(kCli + " register " + dir.path("h.stl") + " " + dir.path("h.stl") + " --roi-center 1,2"), 2);
  EXPECT_EQ(test::run_command(kCli + " import-ct " + dir.path("h.stl") + " -o " + dir.path("x.stl")), 3);
}

}  // namespace
}  // namespace cranioplan
