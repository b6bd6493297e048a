#include "cranioplan/sessions/marker_files.h"

#include <gtest/gtest.h>

#include "cranioplan/model/error.h"
#include "support/test_files.h"

namespace cranioplan {
namespace {

using test::TempDir;

const std::vector<Marker> kMarkers = {
    {1, MarkerType::OuterEdge, {0.1, -2.5, 1e-7}, MarkerSurface::Original},
    {4, MarkerType::InnerEdge, {1.0 / 3.0, 2, 3}, MarkerSurface::Original},
    {7, MarkerType::OuterSurface, {-40.125, 12, 99.999999999}, MarkerSurface::Mirrored},
    {9, MarkerType::InnerSurface, {5, 6, 7}, MarkerSurface::Original}};  // on the original

void expect_same(const std::vector<Marker>& a, const std::vector<Marker>& b) {
  ASSERT_EQ(a.size(), b.size());
  for (size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].id, b[i].id);
    EXPECT_EQ(a[i].type, b[i].type);
    EXPECT_EQ(a[i].surface, b[i].surface);
    EXPECT_EQ(a[i].position, b[i].position) << "positions come back to the last bit";
  }
}

// Expects reading `bytes` as file `name` to be refused with a message naming the file and `part`.
void expect_refused(const TempDir& dir, const std::string& name, const std::string& bytes,
                    const std::string& part) {
  const std::string path = dir.path(name);
  test::write_bytes(path, bytes);
  try {
    read_markers_file(path);
    ADD_FAILURE() << "read " << name;
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()).rfind(path, 0), 0u) << e.what();
    EXPECT_NE(std::string(e.what()).find(part), std::string::npos) << e.what();
  }
}

TEST(MarkerFiles, JsonAndCsvRoundTripsGiveTheSameMarkersExactly) {
  TempDir dir;
  for (const char* name : {"m.json", "m.csv", "M.CSV"}) {
    write_markers_file(kMarkers, dir.path(name));
    expect_same(read_markers_file(dir.path(name)), kMarkers);
  }
  EXPECT_EQ(test::read_bytes(dir.path("m.csv")).substr(0, 22), "id,type,x,y,z,surface\n");
}

TEST(MarkerFiles, CsvFromASpreadsheetIsRead) {
  TempDir dir;
  // Windows line ends, a comment, no header, and the surface left out (each type's own).
  test::write_bytes(dir.path("s.csv"), "# from a spreadsheet\r\n3,0,1,2,3\r\n5,2,4,5,6\r\n");
  const std::vector<Marker> m = read_markers_file(dir.path("s.csv"));
  ASSERT_EQ(m.size(), 2u);
  EXPECT_EQ(m[0].surface, MarkerSurface::Original);
  EXPECT_EQ(m[1].surface, MarkerSurface::Mirrored);
  EXPECT_EQ(m[1].position, Eigen::Vector3d(4, 5, 6));
}

TEST(MarkerFiles, BadFilesAreRefusedNamingTheFileAndThePlace) {
  TempDir dir;
  expect_refused(dir, "type.csv", "1,0,1,2,3\n2,7,1,2,3\n", "line 2: expected id,type(0-3)");
  expect_refused(dir, "short.csv", "1,0,1,2\n", "line 1");
  expect_refused(dir, "nan.csv", "1,0,1,nan,3\n", "line 1");
  expect_refused(dir, "surface.csv", "1,0,1,2,3,left\n", "\"original\" or \"mirrored\"");
  expect_refused(dir, "twice.csv", "1,0,1,2,3\n1,1,1,2,3\n", "marker id 1 is used twice");
  expect_refused(dir, "empty.csv", "id,type,x,y,z\n", "holds no markers");
  expect_refused(dir, "list.json", "[1,2]", "expected {\"markers\": [...]}");
  expect_refused(dir, "key.json", R"({"markers":[{"id":1,"type":0}]})",
                 "marker 1 has no \"position\"");
  expect_refused(dir, "type.json", R"({"markers":[{"id":1,"type":4,"position":[0,0,0]}]})",
                 "marker 1: type must be 0, 1, 2 or 3");
  expect_refused(dir, "id.json", R"({"markers":[{"id":1.5,"type":0,"position":[0,0,0]}]})",
                 "id must be an integer");
  expect_refused(dir, "broken.json", R"({"markers":[)", "");
}

TEST(MarkerFiles, JsonListsEveryFieldOfAMarker) {
  const Json j = markers_to_json({kMarkers[2]});
  ASSERT_EQ(j.at("markers").size(), 1u);
  const Json& m = j["markers"][0];
  EXPECT_EQ(m.at("id"), 7);
  EXPECT_EQ(m.at("type"), 2);
  EXPECT_EQ(m.at("surface"), "mirrored");
  EXPECT_EQ(m.at("position").size(), 3u);
  expect_same(markers_from_json(j, "memory"), {kMarkers[2]});
}

}  // namespace
}  // namespace cranioplan
