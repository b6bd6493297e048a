#include "cranioplan/algorithms/io/read_mesh.h"

#include <gtest/gtest.h>
#include <vtkCellArray.h>
#include <vtkNew.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkXMLPolyDataWriter.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <functional>
#include <limits>

#include "cranioplan/algorithms/io/load_skull.h"
#include "cranioplan/algorithms/io/mesh_report.h"
#include "cranioplan/algorithms/io/write_mesh.h"
#include "cranioplan/model/error.h"
#include "support/synthetic.h"
#include "support/test_files.h"

namespace cranioplan {
namespace {

using test::TempDir;

std::string binary_stl(const std::vector<std::array<float, 9>>& tris, uint32_t declared) {
  std::string s(80, ' ');
  s.append(reinterpret_cast<const char*>(&declared), 4);
  for (const auto& t : tris) {
    s.append(12, '\0');
    s.append(reinterpret_cast<const char*>(t.data()), 36);
    s.append(2, '\0');
  }
  return s;
}

// Expects read_mesh to throw an InputError whose message names the file and contains `part`.
void expect_bad(const std::string& path, const std::string& part) {
  try {
    read_mesh(path);
    FAIL() << "expected an error for " << path;
  } catch (const InputError& e) {
    const std::string msg = e.what();
    EXPECT_EQ(msg.rfind(path, 0), 0u) << msg;
    EXPECT_NE(msg.find(part), std::string::npos) << msg;
  }
}

TEST(ReadMesh, BinaryStlRoundTripWeldsVertices) {
  TempDir dir;
  const SkullMesh head = test::make_symmetric_head(3);
  write_mesh(head, dir.path("head.stl"));
  const MeshFile f = read_mesh(dir.path("head.stl"));
  EXPECT_EQ(f.format, "binary STL");
  EXPECT_EQ(f.mesh.n_faces(), head.n_faces());
  EXPECT_EQ(f.mesh.n_vertices(), head.n_vertices());  // welded back to shared vertices
  EXPECT_TRUE(report_mesh(f.mesh).watertight);
  EXPECT_NEAR(signed_volume(f.mesh), signed_volume(head), 1e-4 * signed_volume(head));
}

TEST(ReadMesh, BinaryStlWhoseHeaderStartsWithSolidIsStillBinary) {
  TempDir dir;
  std::string bytes = binary_stl({{0, 0, 0, 1, 0, 0, 0, 1, 0}}, 1);
  std::memcpy(bytes.data(), "solid trap", 10);
  test::write_bytes(dir.path("trap.stl"), bytes);
  EXPECT_EQ(read_mesh(dir.path("trap.stl")).format, "binary STL");
}

TEST(ReadMesh, PlyRoundTrip) {
  TempDir dir;
  const SkullMesh head = test::make_symmetric_head(2);
  write_mesh(head, dir.path("head.ply"));
  const MeshFile f = read_mesh(dir.path("head.ply"));
  // Meshes are read in canonical order (make_canonical): the head's own soup put in that order.
  TriangleSoup expected = to_soup(head);
  make_canonical(expected);
  TriangleSoup got = to_soup(f.mesh);
  ASSERT_EQ(got.vertices.size(), expected.vertices.size());
  for (size_t i = 0; i < got.vertices.size(); ++i)
    EXPECT_LT((got.vertices[i] - expected.vertices[i]).norm(), 1e-4);  // rounded to float
  make_canonical(got);  // each triangle from its smallest corner, as the expected ones
  EXPECT_EQ(got.triangles, expected.triangles);
}

TEST(ReadMesh, AsciiStlObjOffAndVtp) {
  TempDir dir;
  test::write_bytes(dir.path("a.stl"),
                    "solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\n"
                    "vertex 0 1 0\nendloop\nendfacet\nfacet normal 0 0 1\nouter loop\n"
                    "vertex 1 0 0\nvertex 1 1 0\nvertex 0 1 0\nendloop\nendfacet\nendsolid t\n");
  const MeshFile a = read_mesh(dir.path("a.stl"));
  EXPECT_EQ(a.format, "ASCII STL");
  EXPECT_EQ(a.mesh.n_faces(), 2u);
  EXPECT_EQ(a.mesh.n_vertices(), 4u);

  test::write_bytes(dir.path("q.obj"),
                    "# quad\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1/1 2/2 3/3 4/4\n");
  EXPECT_EQ(read_mesh(dir.path("q.obj")).mesh.n_faces(), 2u);

  test::write_bytes(dir.path("q.off"),
                    "OFF\n# comment\n4 1 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n4 0 1 2 3\n");
  EXPECT_EQ(read_mesh(dir.path("q.off")).mesh.n_faces(), 2u);

  vtkNew<vtkPoints> pts;
  pts->InsertNextPoint(0, 0, 0);
  pts->InsertNextPoint(1, 0, 0);
  pts->InsertNextPoint(0, 1, 0);
  vtkNew<vtkCellArray> polys;
  const vtkIdType ids[3] = {0, 1, 2};
  polys->InsertNextCell(3, ids);
  vtkNew<vtkPolyData> pd;
  pd->SetPoints(pts);
  pd->SetPolys(polys);
  vtkNew<vtkXMLPolyDataWriter> w;
  w->SetInputData(pd);
  w->SetFileName(dir.path("t.vtp").c_str());
  w->Write();
  EXPECT_EQ(read_mesh(dir.path("t.vtp")).mesh.n_faces(), 1u);
}

// A PLY of the unit square (two triangles as one quad) with properties and an element the
// reader must read past: normals, a colour, a face flag and an edge element.
std::string square_ply(const std::string& encoding) {
  std::string s = "ply\r\nformat " + encoding +
                  " 1.0\ncomment made by hand\nelement vertex 4\nproperty float x\n"
                  "property double y\nproperty float z\nproperty float nx\nproperty uchar red\n"
                  "element face 1\nproperty uchar flag\nproperty list uchar uint vertex_indices\n"
                  "element edge 1\nproperty int a\nproperty int b\nend_header\n";
  const float xs[4] = {0, 1, 1, 0};
  const double ys[4] = {0, 0, 1, 1};
  if (encoding == "ascii") {
    for (int i = 0; i < 4; ++i)
      s += std::to_string(xs[i]) + " " + std::to_string(ys[i]) + " 0 0.5 255\n";
    return s + "7 4 0 1 2 3\n0 1\n";
  }
  const bool big = encoding == "binary_big_endian";
  auto put = [&](const auto& value) {
    char b[sizeof(value)];
    std::memcpy(b, &value, sizeof(value));
    if (big) std::reverse(b, b + sizeof(value));
    s.append(b, sizeof(value));
  };
  for (int i = 0; i < 4; ++i) {
    put(xs[i]);
    put(ys[i]);
    put(0.0f);
    put(0.5f);
    put(static_cast<uint8_t>(255));
  }
  put(static_cast<uint8_t>(7));
  put(static_cast<uint8_t>(4));
  for (uint32_t v : {0u, 1u, 2u, 3u}) put(v);
  put(0);
  put(1);
  return s;
}

TEST(ReadMesh, PlyInEveryEncodingWithOtherPropertiesAndElements) {
  TempDir dir;
  for (const char* encoding : {"ascii", "binary_little_endian", "binary_big_endian"}) {
    const std::string p = dir.path(std::string(encoding) + ".ply");
    test::write_bytes(p, square_ply(encoding));
    const MeshFile f = read_mesh(p);
    EXPECT_EQ(f.format, "PLY");
    EXPECT_EQ(f.mesh.n_faces(), 2u) << encoding;
    EXPECT_EQ(f.mesh.n_vertices(), 4u) << encoding;
    EXPECT_NEAR(report_mesh(f.mesh).area_mm2, 1.0, 1e-9) << encoding;
  }
}

TEST(ReadMesh, BadPlyFilesGiveAMessageNotACrash) {
  TempDir dir;
  auto bad = [&](const std::string& name, const std::string& bytes, const std::string& part) {
    test::write_bytes(dir.path(name), bytes);
    expect_bad(dir.path(name), part);
  };
  const std::string ascii = square_ply("ascii");
  const std::string binary = square_ply("binary_little_endian");
  // Each of these crashed VTK's reader (segfault, abort) or was read as nothing.
  bad("truncated.ply", binary.substr(0, binary.size() - 30), "the file ends in item");
  const std::string head = ascii.substr(0, ascii.find("end_header") + 11);
  bad("long-face.ply", head + "0 0 0 0 0\n1 0 0 0 0\n1 1 0 0 0\n0 1 0 0 0\n7 200 0 1 2\n0 1\n",
      "the file ends in item 1 of 1 of element 'face'");
  bad("empty-header.ply", "ply\nformat ascii 1.0\nend_header\n", "no vertex element");
  bad("no-y.ply", "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nend_header\n1\n",
      "no y coordinate");
  bad("no-end.ply", "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n",
      "no 'end_header'");
  bad("no-format.ply", "ply\nelement vertex 0\nend_header\n", "no 'format' line");
  bad("keyword.ply", "ply\nformat ascii 1.0\nvertices 3\nend_header\n",
      "unknown header keyword 'vertices' on header line 3");
  bad("not-ply.ply", "PLY file\n", "does not start with 'ply'");
  bad("index.ply", head + "0 0 0 0 0\n1 0 0 0 0\n1 1 0 0 0\n0 1 0 0 0\n7 3 0 1 9\n0 1\n",
      "face 1 uses vertex 9 but the file has 4 vertices");
  bad("word.ply", head + "0 0 0 0 0\n1 x 0 0 0\n", "'x' is not a number, in item 2 of 4");
  bad("huge.ply",
      "ply\nformat binary_little_endian 1.0\nelement vertex 2000000000\nproperty float x\n"
      "property float y\nproperty float z\nend_header\n" +
          std::string(24, '\0'),
      "the file ends in item 3 of 2,000,000,000 of element 'vertex'");
  // An OBJ face counts its vertices from 1 (or back from the last): the message says so.
  bad("far.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 5\n",
      "face on line 4 uses vertex 5 but only 3 vertices come before it");
  bad("back.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf -1 -2 -4\n", "uses vertex -4 but only 3");
}

TEST(ReadMesh, BadInputsGiveOneClearMessage) {
  TempDir dir;
  expect_bad(dir.path("missing.stl"), "file not found");
  test::write_bytes(dir.path("empty.stl"), "");
  expect_bad(dir.path("empty.stl"), "file is empty");

  const std::array<float, 9> tri{0, 0, 0, 1, 0, 0, 0, 1, 0};
  std::string truncated = binary_stl({tri, tri, tri}, 40000);
  test::write_bytes(dir.path("truncated.stl"), truncated);
  expect_bad(dir.path("truncated.stl"), "file ends after 3 of 40,000 triangles");

  const float nan = std::numeric_limits<float>::quiet_NaN();
  test::write_bytes(dir.path("nan.stl"), binary_stl({tri, {0, 0, 0, nan, 0, 0, 0, 1, 0}}, 2));
  expect_bad(dir.path("nan.stl"), "triangle 2 has a coordinate that is not a number");
  const float inf = std::numeric_limits<float>::infinity();
  test::write_bytes(dir.path("inf.stl"), binary_stl({{0, 0, 0, 1, inf, 0, 0, 1, 0}}, 1));
  expect_bad(dir.path("inf.stl"), "not a number");

  test::write_bytes(dir.path("flat.stl"), binary_stl({{0, 0, 0, 1, 0, 0, 2, 0, 0}}, 1));
  expect_bad(dir.path("flat.stl"), "zero area");

  std::string garbage(5000, '\0');
  for (size_t i = 0; i < garbage.size(); ++i) garbage[i] = static_cast<char>((i * 7919) % 251);
  for (const char* ext : {".stl", ".ply", ".obj", ".off", ".vtp"}) {
    const std::string p = dir.path(std::string("garbage") + ext);
    test::write_bytes(p, garbage);
    EXPECT_THROW(read_mesh(p), InputError) << ext;
  }
  test::write_bytes(dir.path("x.xyz"), "1 2 3");
  expect_bad(dir.path("x.xyz"), "unknown mesh format");
  test::write_bytes(dir.path("bad.off"), "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n");
  expect_bad(dir.path("bad.off"), "uses vertex 7");
  test::write_bytes(dir.path("cut.stl"), "solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0\n");
  expect_bad(dir.path("cut.stl"), "ASCII STL");
  expect_bad(dir.path(""), "folder");
}

TEST(ReadMesh, ABrokenVtpIsOneMessageAndVtkPrintsNothing) {
  TempDir dir;
  test::write_bytes(dir.path("cut.vtp"), "<VTKFile type=\"PolyData\"><PolyData>");
  testing::internal::CaptureStderr();
  expect_bad(dir.path("cut.vtp"), "not a readable VTP file (Error parsing input file.");
  // VTK's executive and XML parser log errors of their own; the user sees ours alone.
  EXPECT_EQ(testing::internal::GetCapturedStderr(), "");
}

TEST(ReadMesh, SomeZeroAreaTrianglesAreDroppedWithAWarningOrRefusedWhenStrict) {
  TempDir dir;
  const std::string p = dir.path("mixed.stl");
  test::write_bytes(p, binary_stl({{0, 0, 0, 1, 0, 0, 0, 1, 0}, {0, 0, 0, 1, 0, 0, 2, 0, 0}}, 2));
  const MeshFile f = read_mesh(p);
  EXPECT_EQ(f.mesh.n_faces(), 1u);
  EXPECT_EQ(f.degenerate_dropped, 1);
  ASSERT_EQ(f.warnings.size(), 1u);
  EXPECT_NE(f.warnings[0].find("1 of 2 triangles have zero area"), std::string::npos);
  ReadMeshParams strict;
  strict.strict = true;
  EXPECT_THROW(read_mesh(p, strict), InputError);
}

TEST(WriteMesh, RefusesUnknownExtensionAndMissingFolder) {
  const SkullMesh head = test::make_symmetric_head(1);
  EXPECT_THROW(write_mesh(head, "/tmp/x.obj"), InputError);
  EXPECT_THROW(write_mesh(head, "/nonexistent-folder-xyz/x.stl"), InputError);
}

}  // namespace
}  // namespace cranioplan

namespace cranioplan {
namespace {

// Every triangle of a binary STL may name three points no other triangle names (a mutated or
// unwelded file): the welder's table, sized for a welded mesh, must grow rather than fill and
// probe for a free slot forever.
TEST(ReadMesh, ABinaryStlOfUnsharedVerticesIsReadNotSpunOn) {
  test::TempDir dir;
  std::vector<std::array<float, 9>> tris;
  for (int t = 0; t < 5000; ++t) {
    const float x = static_cast<float>(t) * 0.01f;
    tris.push_back({x, 0, 0, x, 1, 0, x, 0, 1});
  }
  test::write_bytes(dir.path("unshared.stl"), binary_stl(tris, static_cast<uint32_t>(tris.size())));
  const MeshFile f = read_mesh(dir.path("unshared.stl"));
  EXPECT_EQ(f.mesh.n_vertices(), 15000u);
  EXPECT_EQ(f.mesh.n_faces(), 5000u);
}

}  // namespace
}  // namespace cranioplan
