#include "cranioplan/sessions/plan_files.h"

#include <gtest/gtest.h>

#include "cranioplan/model/error.h"
#include "support/test_files.h"

namespace cranioplan {
namespace {

TEST(PlanFiles, LandmarksPlaneAndTransformRoundTrip) {
  test::TempDir dir;
  Landmarks lm;
  lm.nasion = Eigen::Vector3d(0, 90, 10);
  lm.orbit_left = Eigen::Vector3d(-30, 80, 5);
  lm.orbit_right = Eigen::Vector3d(30, 80, 5);
  lm.midline = {{0, -90, 20}};
  write_json_file(to_json(lm), dir.path("lm.json"));
  const Landmarks back = read_landmarks_file(dir.path("lm.json"));
  EXPECT_EQ(*back.nasion, *lm.nasion);
  EXPECT_EQ(back.midline.size(), 1u);

  const Plane p = Plane::through({1, 2, 3}, {0.6, 0.8, 0});
  write_json_file(to_json(p), dir.path("plane.json"));
  const Plane q = read_plane_file(dir.path("plane.json"));
  EXPECT_LT((q.normal - p.normal).norm(), 1e-15);
  EXPECT_DOUBLE_EQ(q.offset, p.offset);

  const RigidTransform t = RigidTransform::from_axis_angle({1, 1, 0}, 20, {1, 2, 3});
  const RigidTransform u = transform_from_json(to_json(t), "t.json");
  EXPECT_LT((u.rotation - t.rotation).norm(), 1e-15);
}

TEST(PlanFiles, BadFilesNameTheFileAndTheProblem) {
  test::TempDir dir;
  test::write_bytes(dir.path("broken.json"), "{\"nasion\": [1, 2,");
  try {
    read_landmarks_file(dir.path("broken.json"));
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("not valid JSON"), std::string::npos);
  }
  // A number past a double's range: nlohmann's out_of_range, not a parse_error; it aborted.
  test::write_bytes(dir.path("huge.json"), "{\"nasion\": [1e400, 0, 0]}");
  try {
    read_landmarks_file(dir.path("huge.json"));
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("not valid JSON (number overflow parsing '1e400')"),
              std::string::npos)
        << e.what();
  }
  test::write_bytes(dir.path("few.json"), "{\"nasion\": [1, 2, 3]}");
  EXPECT_THROW(read_landmarks_file(dir.path("few.json")), InputError);
  test::write_bytes(
      dir.path("text.json"),
      "{\"nasion\": [1, \"a\", 3], \"orbit_left\": [0,0,0], \"orbit_right\": [9,0,0]}");
  EXPECT_THROW(read_landmarks_file(dir.path("text.json")), InputError);
  test::write_bytes(dir.path("zero.json"), "{\"normal\": [0, 0, 0], \"offset_mm\": 1}");
  EXPECT_THROW(read_plane_file(dir.path("zero.json")), InputError);
  test::write_bytes(dir.path("empty.json"), "  \n");
  EXPECT_THROW(read_plane_file(dir.path("empty.json")), InputError);
  EXPECT_THROW(read_plane_file(dir.path("missing.json")), InputError);
  Json notrot = to_json(RigidTransform{});
  notrot["rotation"][0][0] = 2.0;
  EXPECT_THROW(transform_from_json(notrot, "t.json"), InputError);
}

}  // namespace
}  // namespace cranioplan
