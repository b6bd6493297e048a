#include "cranioplan/sessions/slicer_markups.h"

#include <gtest/gtest.h>

#include "cranioplan/model/error.h"
#include "cranioplan/sessions/marker_files.h"
#include "support/session_cases.h"
#include "support/test_files.h"

namespace cranioplan {
namespace {

using test::TempDir;

const std::vector<Marker> kMarkers = {
    {3, MarkerType::OuterEdge, {-10.25, 33.5, 101.0 / 3.0}, MarkerSurface::Original},
    {4, MarkerType::OuterEdge, {-12, 30, 99}, MarkerSurface::Original},
    {9, MarkerType::InnerEdge, {-11, 31, 95}, MarkerSurface::Original},
    {12, MarkerType::OuterSurface, {1e-9, -7, 120.125}, MarkerSurface::Mirrored},
    {20, MarkerType::InnerSurface, {2, -6, 115}, MarkerSurface::Original}};

std::string schema() {
  return std::string(CRANIOPLAN_SOURCE_DIR) + "/tests/support/slicer-markups.schema.json";
}

// Validates a file against the markups schema (skipped without python3-jsonschema).
void expect_valid(const std::string& path) {
  const std::string check = test::validate_json_schema(path, schema());
  if (check != "skip") {
    EXPECT_EQ(check, "") << path;
  }
}

std::string error_of(const std::string& path) {
  try {
    read_markers_file(path);
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()).rfind(path, 0), 0u) << e.what();
    return e.what();
  }
  return "";
}

TEST(SlicerMarkups, MarkersOutAndInAreTheSameMarkers) {
  TempDir dir;
  const std::string path = dir.path("plan.mrk.json");
  write_markers_file(kMarkers, path);
  expect_valid(path);
  const std::vector<Marker> back = read_markers_file(path);
  ASSERT_EQ(back.size(), kMarkers.size());
  for (size_t i = 0; i < back.size(); ++i) {
    EXPECT_EQ(back[i].id, kMarkers[i].id);
    EXPECT_EQ(back[i].type, kMarkers[i].type);
    EXPECT_EQ(back[i].surface, kMarkers[i].surface);
    EXPECT_EQ(back[i].position, kMarkers[i].position) << "to the last bit";
  }
  // One list per type, in LPS millimetres, each point labelled with its type and id.
  const Json j = read_json_file(path);
  ASSERT_EQ(j["markups"].size(), 4u);
  EXPECT_EQ(j["markups"][0]["name"], "outer edge");
  EXPECT_EQ(j["markups"][0]["coordinateSystem"], "LPS");
  EXPECT_EQ(j["markups"][0]["controlPoints"][1]["label"], "outer edge 4");
  EXPECT_EQ(j["markups"][2]["controlPoints"][0]["description"], "mirrored");
}

TEST(SlicerMarkups, LandmarksOutAndIn) {
  TempDir dir;
  Landmarks lm;
  lm.nasion = Eigen::Vector3d(0.5, -90, 10);
  lm.orbit_left = Eigen::Vector3d(32, -80, 5);
  lm.orbit_right = Eigen::Vector3d(-31, -79, 4);
  lm.midline = {{0, 0, 120}, {0.25, 60, 80}};
  const std::string path = dir.path("lm.mrk.json");
  write_landmarks_file(lm, path);
  expect_valid(path);
  const Landmarks back = read_landmarks_file(path);
  EXPECT_EQ(back.nasion, lm.nasion);
  EXPECT_EQ(back.orbit_left, lm.orbit_left);
  EXPECT_EQ(back.orbit_right, lm.orbit_right);
  EXPECT_EQ(back.midline, lm.midline);
}

// A list as Slicer writes it by hand: RAS, micrometres, Slicer's own ids, a point not placed,
// types in the labels only.
TEST(SlicerMarkups, AListMadeInSlicerIsRead) {
  TempDir dir;
  const std::string path = dir.path("F.mrk.json");
  test::write_bytes(
      path,
      R"({"@schema": "https://raw.githubusercontent.com/slicer/slicer/master/Modules/Loadable/Markups/Resources/Schema/markups-schema-v1.0.3.json#",
  "markups": [{"type": "Line", "coordinateSystem": "LPS", "controlPoints": []},
   {"type": "Fiducial", "name": "F", "coordinateSystem": "RAS", "coordinateUnits": "um",
    "controlPoints": [
     {"id": "1", "label": "Outer_Edge-1", "position": [10000.0, 20000.0, 30000.0], "positionStatus": "defined"},
     {"id": "1", "label": "outer edge 2", "position": [11000.0, 20000.0, 30000.0]},
     {"id": "3", "label": "F-3", "position": [0, 0, 0], "positionStatus": "undefined"},
     {"id": "vtkMRMLMarkupsFiducialNode1", "label": "inner surface", "description": "mirrored",
      "position": [-5000.0, 1000.0, 2000.0], "positionStatus": "defined"}]}]})");
  expect_valid(path);
  const std::vector<Marker> m = read_markers_file(path);
  ASSERT_EQ(m.size(), 3u) << "the undefined point is left out";
  EXPECT_EQ(m[0].type, MarkerType::OuterEdge);
  EXPECT_EQ(m[0].position, Eigen::Vector3d(-10, -20, 30)) << "RAS to LPS, um to mm";
  EXPECT_EQ(m[0].id, 1);
  EXPECT_EQ(m[1].id, 2) << "an id used twice takes the next free one";
  EXPECT_EQ(m[2].type, MarkerType::InnerSurface);
  EXPECT_EQ(m[2].surface, MarkerSurface::Mirrored);
  EXPECT_EQ(m[2].id, 3);
}

TEST(SlicerMarkups, FilesThatCannotBeReadSayWhy) {
  TempDir dir;
  auto bad = [&](const std::string& name, const std::string& bytes, const std::string& part) {
    test::write_bytes(dir.path(name), bytes);
    EXPECT_NE(error_of(dir.path(name)).find(part), std::string::npos)
        << error_of(dir.path(name)) << " (wanted: " << part << ")";
  };
  bad("untyped.mrk.json",
      R"({"markups":[{"type":"Fiducial","name":"F","controlPoints":[{"label":"F-1","position":[1,2,3]}]}]})",
      "list 'F', point 1 does not say which marker it is: name the list, or label the point");
  bad("curve.mrk.json", R"({"markups":[{"type":"Curve","controlPoints":[{"position":[1,2,3]}]}]})",
      "no defined point in a fiducial list (it holds Curve markups, which are not read)");
  bad("space.mrk.json",
      R"({"markups":[{"type":"Fiducial","coordinateSystem":"IJK","controlPoints":[]}]})",
      "coordinate system must be LPS or RAS, not 'IJK'");
  bad("nopos.mrk.json",
      R"({"markups":[{"type":"Fiducial","name":"outer edge","controlPoints":[{"label":"a"}]}]})",
      "list 'outer edge', point 1 position");
  bad("plain.mrk.json", R"({"markers":[]})", "not a Slicer markups file");
  test::write_bytes(
      dir.path("lm.mrk.json"),
      R"({"markups":[{"type":"Fiducial","controlPoints":[{"label":"bregma","position":[1,2,3]}]}]})");
  try {
    read_landmarks_file(dir.path("lm.mrk.json"));
    ADD_FAILURE();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("is labelled 'bregma': landmarks are labelled nasion"),
              std::string::npos)
        << e.what();
  }
}

TEST(SlicerMarkups, TheCliWritesAPlansPointsAsMarkups) {
  TempDir dir;
  const std::string session = test::planned_defect_case().session_path;
  const std::string markers = dir.path("m.mrk.json"), landmarks = dir.path("l.mrk.json");
  ASSERT_EQ(test::run_command(std::string(CRANIOPLAN_CLI) + " points '" + session +
                              "' --markers '" + markers + "' --landmarks '" + landmarks + "'"),
            0);
  EXPECT_GT(read_markers_file(markers).size(), 20u);
  expect_valid(markers);
  EXPECT_TRUE(read_landmarks_file(landmarks).empty()) << "the automatic plan sets none";
}

}  // namespace
}  // namespace cranioplan
