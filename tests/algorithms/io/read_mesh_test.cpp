#include "cranioplan/algorithms/io/read_mesh.h"

#include <gtest/gtest.h>
#include <vtkCellArray.h>
#include <vtkDoubleArray.h>
#include <vtkFieldData.h>
#include <vtkNew.h>
#include <vtkPLYWriter.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkPolyDataWriter.h>
#include <vtkSTLWriter.h>
#include <vtkStringArray.h>
#include <vtkXMLPolyDataWriter.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <functional>
#include <limits>

#include "cranioplan/algorithms/io/load_skull.h"
#include "cranioplan/algorithms/io/mesh_report.h"
#include "cranioplan/algorithms/io/write_mesh.h"
#include "cranioplan/model/error.h"
#include "support/synthetic.h"
#include "support/test_files.h"
#include "support/vtk_meshes.h"

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

// 3D Slicer declares a mesh file's coordinate system ("SPACE=RAS" or "SPACE=LPS") in an STL's
// header, a legacy VTK file's header line (Slicer's default model format), a PLY's or an OBJ's
// comment and a VTP's field data "SPACE", written here by VTK's own
// writers as Slicer calls them. Declared RAS, the mesh is read in the patient's LPS when asked:
// x and y negated, the winding (and so the enclosed volume) kept.
Eigen::Vector3d lowest_corner(const SkullMesh& mesh) {
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(1e30);
  for (auto vh : mesh.vertices()) lo = lo.cwiseMin(to_eigen(mesh.point(vh)));
  return lo;
}
Eigen::Vector3d highest_corner(const SkullMesh& mesh) {
  Eigen::Vector3d hi = Eigen::Vector3d::Constant(-1e30);
  for (auto vh : mesh.vertices()) hi = hi.cwiseMax(to_eigen(mesh.point(vh)));
  return hi;
}

TEST(ReadMesh, TheSpaceAFileDeclaresIsReadAsSlicerWritesIt) {
  TempDir dir;
  SkullMesh head = test::make_symmetric_head(3);
  for (auto vh : head.vertices()) head.point(vh) += SkullMesh::Point(30, 50, 10);  // off-centre
  const vtkSmartPointer<vtkPolyData> pd = test::to_polydata(head);
  auto stl = [&](const std::string& name, bool ascii, const char* header) {
    vtkNew<vtkSTLWriter> w;
    w->SetInputData(pd);
    w->SetFileName(dir.path(name).c_str());
    if (ascii)
      w->SetFileTypeToASCII();
    else
      w->SetFileTypeToBinary();
    w->SetHeader(header);
    w->Write();
    return dir.path(name);
  };
  auto ply = [&](const std::string& name, const char* comment) {
    vtkNew<vtkPLYWriter> w;
    w->SetInputData(pd);
    w->SetFileName(dir.path(name).c_str());
    w->AddComment(comment);
    w->Write();
    return dir.path(name);
  };
  auto vtp = [&](const std::string& name, const char* space) {
    vtkNew<vtkPolyData> tagged;
    tagged->ShallowCopy(pd);
    vtkNew<vtkStringArray> tag;
    tag->SetName("SPACE");
    tag->InsertNextValue(space);
    tagged->GetFieldData()->AddArray(tag);
    vtkNew<vtkXMLPolyDataWriter> w;
    w->SetInputData(tagged);
    w->SetFileName(dir.path(name).c_str());
    w->Write();
    return dir.path(name);
  };
  auto legacy = [&](const std::string& name, bool binary, const char* header) {
    vtkNew<vtkPolyDataWriter> w;  // as Slicer writes its default model format
    w->SetInputData(pd);
    w->SetFileName(dir.path(name).c_str());
    w->SetFileVersion(42);
    if (binary)
      w->SetFileTypeToBinary();
    else
      w->SetFileTypeToASCII();
    w->SetHeader(header);
    w->Write();
    return dir.path(name);
  };
  auto obj = [&](const std::string& name, const char* comment) {
    std::string text = std::string("# ") + comment + "\n";
    char line[96];
    for (auto vh : head.vertices()) {
      const auto& p = head.point(vh);
      std::snprintf(line, sizeof(line), "v %.9g %.9g %.9g\n", p[0], p[1], p[2]);
      text += line;
    }
    for (auto fh : head.faces()) {
      text += "f";
      for (auto vh : head.fv_range(fh)) text += " " + std::to_string(vh.idx() + 1);
      text += "\n";
    }
    test::write_bytes(dir.path(name), text);
    return dir.path(name);
  };
  const std::vector<std::pair<std::string, MeshSpace>> files = {
      {stl("ras_binary.stl", false, "3D Slicer output. SPACE=RAS"), MeshSpace::RAS},
      {stl("ras_ascii.stl", true, "3D Slicer output. SPACE=RAS"), MeshSpace::RAS},
      {ply("ras.ply", "SPACE=RAS"), MeshSpace::RAS},
      {obj("ras.obj", "3D Slicer output. SPACE=RAS"), MeshSpace::RAS},
      {vtp("ras.vtp", "RAS"), MeshSpace::RAS},
      {legacy("ras_binary.vtk", true, "3D Slicer output. SPACE=RAS"), MeshSpace::RAS},
      {legacy("ras_ascii.vtk", false, "3D Slicer output. SPACE=RAS"), MeshSpace::RAS},
      {legacy("lps.vtk", true, "3D Slicer output. SPACE=LPS"), MeshSpace::LPS},
      {stl("lps.stl", false, "3D Slicer output. SPACE=LPS"), MeshSpace::LPS},
      {ply("lps.ply", "SPACE=LPS"), MeshSpace::LPS},
      {vtp("lps.vtp", "LPS"), MeshSpace::LPS},
      {stl("plain.stl", false, "Visualization Toolkit generated SLA File"), MeshSpace::Undeclared},
      {obj("plain.obj", "made by hand"), MeshSpace::Undeclared}};
  const Eigen::Vector3d lo = lowest_corner(head), hi = highest_corner(head);
  const double volume = signed_volume(head);
  for (const auto& [path, declared] : files) {
    SCOPED_TRACE(path);
    const MeshFile as_is = read_mesh(path);
    EXPECT_EQ(as_is.space, declared);
    EXPECT_FALSE(as_is.turned_to_lps);
    EXPECT_LT((lowest_corner(as_is.mesh) - lo).norm(), 1e-4);
    ReadMeshParams lps;
    lps.space_from_header = true;
    const MeshFile read = read_mesh(path, lps);
    EXPECT_EQ(read.turned_to_lps, declared == MeshSpace::RAS);
    const Eigen::Vector3d want_lo =
        declared == MeshSpace::RAS ? Eigen::Vector3d(-hi.x(), -hi.y(), lo.z()) : lo;
    EXPECT_LT((lowest_corner(read.mesh) - want_lo).norm(), 1e-4);
    EXPECT_NEAR(signed_volume(read.mesh), volume, 1e-4 * volume) << "wound as before";
  }
  // What the project writes in RAS says so, and reads back where it was.
  const std::string back = dir.path("back.stl");
  write_mesh(head, back, MeshSpace::RAS);
  ReadMeshParams lps;
  lps.space_from_header = true;
  const MeshFile round = read_mesh(back, lps);
  EXPECT_EQ(round.space, MeshSpace::RAS);
  EXPECT_LT((lowest_corner(round.mesh) - lo).norm(), 1e-4);
  EXPECT_LT(
      (lowest_corner(read_mesh(back).mesh) - Eigen::Vector3d(-hi.x(), -hi.y(), lo.z())).norm(),
      1e-4);
  EXPECT_NEAR(signed_volume(round.mesh), volume, 1e-4 * volume);
  EXPECT_EQ(encode_mesh(head, MeshFormat::BinarySTL),
            encode_mesh(head, MeshFormat::BinarySTL, MeshSpace::LPS))
      << "nothing declared, nothing turned, but for RAS";
}

// An OBJ face counts its vertices from 1 (or back from the last): the message says so.
TEST(ReadMesh, ObjFacesOutOfRangeSayHowObjCounts) {
  TempDir dir;
  test::write_bytes(dir.path("far.obj"), "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 5\n");
  expect_bad(dir.path("far.obj"),
             "face on line 4 uses vertex 5 but only 3 vertices come before it");
  test::write_bytes(dir.path("back.obj"), "v 0 0 0\nv 1 0 0\nv 0 1 0\nf -1 -2 -4\n");
  expect_bad(dir.path("back.obj"), "uses vertex -4 but only 3");
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
  // A text file saved as .stl (a note, an error page): said to be text, not a count of
  // triangles read from its letters.
  test::write_bytes(dir.path("note.stl"),
                    "Patient notes: skull CT 2026-03-01, frontal defect after decompression.\n"
                    "Second line of the note, long enough to pass 84 bytes.\n");
  expect_bad(dir.path("note.stl"), "not an STL file: it is text (beginning \"Patient notes");
  // A binary header whose count no file could hold: not taken for a truncated STL.
  std::string other = binary_stl({tri}, 1);
  const uint32_t huge = 1'851'878'512u;
  std::memcpy(other.data() + 80, &huge, 4);
  other[0] = '\x01';  // not text
  test::write_bytes(dir.path("other.stl"), other);
  expect_bad(dir.path("other.stl"), "not an STL file: its header would declare 1,851,878,512");

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
  for (const char* ext : {".stl", ".ply", ".obj", ".off", ".vtk", ".vtp"}) {
    const std::string p = dir.path(std::string("garbage") + ext);
    test::write_bytes(p, garbage);
    EXPECT_THROW(read_mesh(p), InputError) << ext;
  }
  expect_bad(dir.path("garbage.vtk"), "not a VTK polygonal data file");
  // A legacy VTK file of another kind (Slicer also writes unstructured grids as .vtk).
  test::write_bytes(dir.path("grid.vtk"),
                    "# vtk DataFile Version 4.2\ngrid\nASCII\nDATASET UNSTRUCTURED_GRID\n"
                    "POINTS 3 float\n0 0 0 1 0 0 0 1 0\nCELLS 1 4\n3 0 1 2\nCELL_TYPES 1\n5\n");
  expect_bad(dir.path("grid.vtk"), "not a VTK polygonal data file");
  // Cut short after its points.
  test::write_bytes(dir.path("cut.vtk"),
                    "# vtk DataFile Version 4.2\ncut\nASCII\nDATASET POLYDATA\n"
                    "POINTS 3 float\n0 0 0 1 0 0 0 1 0\nPOLYGONS 1 4\n3 0 1\n");
  EXPECT_THROW(read_mesh(dir.path("cut.vtk")), InputError);
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

// A VTP's arrays are compressed, so its size says nothing of what reading it takes: its pieces'
// counts do. A file that declares more points than half the machine's memory can read is
// refused before it is read, at once; one whose point data takes more than a mesh of its points
// and cells does (one array of 300 doubles a point: 480 MB of zeros in a file of 2 MB) ends its
// reader's child with a message, not the machine's memory. The head itself reads as before.
TEST(ReadMesh, AVtpThatWouldFillTheMemoryIsRefused) {
  TempDir dir;
  const SkullMesh head = test::make_symmetric_head(3);
  vtkNew<vtkXMLPolyDataWriter> w;
  w->SetInputData(test::to_polydata(head));
  w->SetFileName(dir.path("head.vtp").c_str());
  w->SetDataModeToAppended();
  w->Write();
  EXPECT_EQ(read_mesh(dir.path("head.vtp")).mesh.n_faces(), head.n_faces());
  std::string bytes = test::read_bytes(dir.path("head.vtp"));
  const std::string declared = "NumberOfPoints=\"" + std::to_string(head.n_vertices()) + "\"";
  const size_t at = bytes.find(declared);
  ASSERT_NE(at, std::string::npos);
  bytes.replace(at, declared.size(), "NumberOfPoints=\"100000000000\"");
  test::write_bytes(dir.path("huge.vtp"), bytes);
  const auto t0 = std::chrono::steady_clock::now();
  expect_bad(dir.path("huge.vtp"), "declares 100,000,000,000 points");
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), 30.0)
      << "refused before it is read";

  const vtkIdType n = 200000;
  vtkNew<vtkPoints> points;
  points->SetDataTypeToDouble();
  points->SetNumberOfPoints(n);
  points->GetData()->Fill(0.0);
  for (vtkIdType i = 0; i < 3; ++i) points->SetPoint(i, i == 1, i == 2, 0.0);
  vtkNew<vtkCellArray> polys;
  const vtkIdType ids[3] = {0, 1, 2};
  polys->InsertNextCell(3, ids);
  vtkNew<vtkDoubleArray> data;
  data->SetName("data");
  data->SetNumberOfComponents(300);
  data->SetNumberOfTuples(n);
  data->Fill(0.0);
  vtkNew<vtkPolyData> pd;
  pd->SetPoints(points);
  pd->SetPolys(polys);
  pd->GetPointData()->AddArray(data);
  vtkNew<vtkXMLPolyDataWriter> bomb;
  bomb->SetInputData(pd);
  bomb->SetFileName(dir.path("arrays.vtp").c_str());
  bomb->SetDataModeToAppended();
  bomb->Write();
  EXPECT_LT(std::filesystem::file_size(dir.path("arrays.vtp")), 20u * 1024 * 1024);
  expect_bad(dir.path("arrays.vtp"),
             "its arrays take more memory than a mesh of 200,000 points and 1 cell does");
}

// A binary legacy VTK file cut short: VTK's reader reads on past its end (other triangles on
// each run, or a crash in its child process), so the sections are checked against the file's
// size first, in both versions VTK writes. One message naming the file; VTK prints nothing.
TEST(ReadMesh, ABrokenLegacyVtkIsOneMessageAndVtkPrintsNothing) {
  TempDir dir;
  const SkullMesh head = test::make_symmetric_head(4);
  for (const int version : {42, 51}) {
    vtkNew<vtkPolyDataWriter> w;
    w->SetInputData(test::to_polydata(head));
    const std::string whole = dir.path("whole" + std::to_string(version) + ".vtk");
    w->SetFileName(whole.c_str());
    w->SetFileVersion(version);
    w->SetFileTypeToBinary();
    w->Write();
    EXPECT_EQ(read_mesh(whole).mesh.n_faces(), head.n_faces()) << version;
    const std::string bytes = test::read_bytes(whole);
    for (const double keep : {0.2, 0.5, 0.8}) {
      SCOPED_TRACE(std::to_string(version) + " cut at " + std::to_string(keep));
      const std::string cut = dir.path("cut.vtk");
      // Cut inside the geometry: points take the first part, the polygons the rest.
      const size_t end =
          bytes.find("POINT_DATA") == std::string::npos ? bytes.size() : bytes.find("POINT_DATA");
      test::write_bytes(cut, bytes.substr(0, static_cast<size_t>(keep * end)));
      testing::internal::CaptureStderr();
      expect_bad(cut, "cut short");
      EXPECT_EQ(testing::internal::GetCapturedStderr(), "");
    }
  }
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

// A binary STL is read in blocks: a file of several blocks, whose triangles straddle the
// blocks' ends, with a few bytes after the last triangle (as some exporters pad), gives every
// triangle as written; a file cut short or with a NaN in a later block gives its message.
TEST(ReadMesh, ABinaryStlOfSeveralReadBlocksIsReadWhole) {
  test::TempDir dir;
  std::vector<std::array<float, 9>> tris;
  for (int t = 0; t < 25013; ++t) {
    const float x = static_cast<float>(t % 211) * 0.5f, y = static_cast<float>(t / 211) * 0.5f;
    tris.push_back({x, y, 0, x + 0.5f, y, 0.25f, x, y + 0.5f, 0.125f});
  }
  std::string bytes = binary_stl(tris, static_cast<uint32_t>(tris.size()));
  test::write_bytes(dir.path("big.stl"), bytes + std::string(17, '\x01'));
  const TriangleSoup soup = read_mesh_soup(dir.path("big.stl"));
  ASSERT_EQ(soup.triangles.size(), tris.size());
  for (size_t t = 0; t < tris.size(); ++t)
    for (int v = 0; v < 3; ++v)
      for (int c = 0; c < 3; ++c)
        ASSERT_EQ(soup.vertices[soup.triangles[t][v]][c], tris[t][3 * v + c]) << t;

  test::write_bytes(dir.path("short.stl"), bytes.substr(0, bytes.size() - 70));
  expect_bad(dir.path("short.stl"), "file ends after 25,011 of 25,013 triangles");
  std::string nan = bytes;
  const float bad = std::numeric_limits<float>::quiet_NaN();
  std::memcpy(nan.data() + 84 + 50 * 20000 + 12 + 4 * 4, &bad, 4);
  test::write_bytes(dir.path("nan.stl"), nan);
  expect_bad(dir.path("nan.stl"), "triangle 20,001 has a coordinate that is not a number");
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
