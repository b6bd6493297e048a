#include "cranioplan/algorithms/io/load_skull.h"

#include <gtest/gtest.h>
#include <vtkNew.h>
#include <vtkSTLWriter.h>

#include <cmath>

#include "cranioplan/algorithms/io/mesh_report.h"
#include "cranioplan/algorithms/io/write_mesh.h"
#include "cranioplan/model/error.h"
#include "support/synthetic.h"
#include "support/test_files.h"
#include "support/vtk_meshes.h"

namespace cranioplan {
namespace {

using test::TempDir;

// A head about 180 mm across, written in another unit: refused as a skull, naming the unit
// that makes it head-sized, and read at its size in that unit.
TEST(LoadSkull, ASkullInAnotherUnitIsRefusedNamingTheUnitAndReadInIt) {
  TempDir dir;
  const SkullMesh head = test::make_symmetric_head(2);
  const MeshReport size = report_mesh(head);
  const double extent = (size.bbox_max - size.bbox_min).maxCoeff();
  ASSERT_GT(extent, kSkullMinExtentMm);
  ASSERT_LT(extent, kSkullMaxExtentMm);
  struct Case {
    const char* unit;
    const char* label;
  };
  for (const Case c : {Case{"m", "metres"}, Case{"in", "inches"}, Case{"cm", "centimetres"}}) {
    const double unit_mm = length_unit_named(c.unit)->mm;
    const std::string p = dir.path(std::string("head-") + c.unit + ".stl");
    write_mesh(test::scaled(head, 1.0 / unit_mm), p);
    try {
      load_skull(p);
      ADD_FAILURE() << "a head in " << c.label << " was planned as millimetres";
    } catch (const InputError& e) {
      const std::string msg = e.what();
      EXPECT_EQ(msg.rfind(p, 0), 0u) << msg;
      EXPECT_NE(msg.find(std::string("looks to be in ") + c.label), std::string::npos) << msg;
      EXPECT_NE(msg.find(std::string("(length unit '") + c.unit + "')"), std::string::npos) << msg;
    }
    // Any surface may be read as it is (an implant, a test shape): no size to check.
    EXPECT_EQ(load_surface(p).mesh.n_faces(), head.n_faces());
    ExtractBoneSurfaceParams in_unit;
    in_unit.mesh_unit_mm = unit_mm;
    const LoadedSkull read = load_skull(p, in_unit);
    const MeshReport got = report_mesh(read.mesh);
    EXPECT_NEAR((got.bbox_max - got.bbox_min).maxCoeff(), extent, 1e-3 * extent) << c.unit;
  }
  // No unit makes a 2 mm part a skull; a volume of the wrong size points at its spacing.
  const SkullMesh tiny = test::scaled(head, 0.01);
  write_mesh(tiny, dir.path("tiny.stl"));
  auto refusal = [](const std::function<void()>& load) {
    try {
      load();
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("(taken for a skull)");
  };
  EXPECT_NE(refusal([&] {
              load_skull(dir.path("tiny.stl"));
            }).find("it is no skull, or not in a length unit Cranioplan reads"),
            std::string::npos);
  EXPECT_NE(refusal([&] {
              check_skull_size(tiny, "ct.nrrd", 0.0);
            }).find("check the voxel spacing in the volume's header"),
            std::string::npos);
  EXPECT_FALSE(length_unit_named("furlong"));
}

// A skull closed by the padding where its scan ended: the cap is a note of what the mesh has,
// not a warning (the warnings are the repair report a plan records).
TEST(LoadSkull, AFlatCapWhereTheScanEndedIsANoteNotAWarning) {
  TempDir dir;
  const SkullMesh head = test::make_thick_head(0.93, 1.0);
  const MeshReport whole = report_mesh(head);
  write_mesh(test::scanned_padded(head, Eigen::Vector3d(0, 0, whole.bbox_min.z() + 30.0),
                                  Eigen::Vector3d::UnitZ()),
             dir.path("padded.stl"));
  const std::string path = dir.path("padded.stl");
  const LoadedSkull loaded = load_skull(path);
  ASSERT_EQ(loaded.notes.size(), 1u);
  EXPECT_EQ(loaded.notes[0].rfind(path + ": closed by a flat cap at its lower border", 0), 0u)
      << loaded.notes[0];
  for (const std::string& w : loaded.warnings) EXPECT_EQ(w.find("cap"), std::string::npos) << w;
  // The report the note came from is kept, for planning to take the scan's end from.
  ASSERT_TRUE(loaded.report.has_value());
  EXPECT_EQ(loaded.report->caps.size(), 1u);
  EXPECT_TRUE(loaded.report->watertight);
  EXPECT_FALSE(load_surface(path).report.has_value()) << "an implant is not a skull";
}

// Some exporters wind triangles the other way: the skull then encloses a negative volume and
// its normals point in, which the detection reads as inner and outer tables swapped (the
// sample turned inside out: "too little intact bone around the opening (0 rays)"). load_skull
// turns it outward, with a warning, into the very mesh the outward file gives; load_surface
// (an implant for the quality check) keeps it as it is.
TEST(LoadSkull, ASkullThatWindsInwardIsTurnedOutward) {
  TempDir dir;
  const SkullMesh head =
      test::cut_hole(test::make_symmetric_head(3),
                     test::head_surface_point(Eigen::Vector3d(0.7, 0.1, 0.7).normalized()), 25);
  TriangleSoup inward = to_soup(head);
  for (auto& t : inward.triangles) std::swap(t[1], t[2]);
  write_mesh(head, dir.path("out.stl"));
  write_mesh(build_mesh(inward), dir.path("in.stl"));
  ASSERT_LT(signed_volume(load_surface(dir.path("in.stl")).mesh), 0.0) << "kept as it is";
  const LoadedSkull turned = load_skull(dir.path("in.stl"));
  EXPECT_GT(signed_volume(turned.mesh), 0.0);
  // The turn, and (as for any skull with a hole) where the surface is open.
  ASSERT_EQ(turned.warnings.size(), 2u);
  EXPECT_NE(turned.warnings[0].find("inside out"), std::string::npos) << turned.warnings[0];
  EXPECT_NE(turned.warnings[1].find("1 hole in the surface"), std::string::npos)
      << turned.warnings[1];
  const LoadedSkull outward = load_skull(dir.path("out.stl"));
  ASSERT_EQ(outward.warnings.size(), 1u);
  EXPECT_EQ(outward.warnings[0].substr(outward.warnings[0].find(": ")),
            turned.warnings[1].substr(turned.warnings[1].find(": ")));
  const TriangleSoup a = to_soup(turned.mesh), b = to_soup(outward.mesh);
  EXPECT_EQ(a.triangles, b.triangles);
  EXPECT_EQ(a.vertices, b.vertices);
  ExtractBoneSurfaceParams as_it_came;
  as_it_came.orient_outward = false;
  EXPECT_LT(signed_volume(load_skull(dir.path("in.stl"), as_it_came).mesh), 0.0);
}

// Whether triangle `t`'s centroid lies within `radius` of `centre`.
bool centroid_within(const TriangleSoup& s, const Eigen::Vector3i& t, const Eigen::Vector3d& centre,
                     double radius) {
  return ((s.vertices[t[0]] + s.vertices[t[1]] + s.vertices[t[2]]) / 3.0 - centre).norm() < radius;
}

// `clean` and `damaged` written as STL and read as skulls: the damaged file gives the clean
// mesh (the same vertices and triangles in the same order) with one warning more, its first,
// which names the file and says `says`. The damaged file's path.
std::string expect_repaired(const TempDir& dir, const SkullMesh& clean, const TriangleSoup& damaged,
                            const std::string& says) {
  write_mesh(clean, dir.path("clean.stl"));
  write_mesh(build_mesh(damaged), dir.path("damaged.stl"));
  const LoadedSkull repaired = load_skull(dir.path("damaged.stl"));
  const LoadedSkull as_clean = load_skull(dir.path("clean.stl"));
  const TriangleSoup a = to_soup(repaired.mesh), b = to_soup(as_clean.mesh);
  EXPECT_EQ(a.triangles, b.triangles);
  EXPECT_EQ(a.vertices, b.vertices);
  EXPECT_EQ(repaired.warnings.size(), as_clean.warnings.size() + 1);
  EXPECT_FALSE(repaired.warnings.empty());
  if (!repaired.warnings.empty()) {
    EXPECT_NE(repaired.warnings[0].find("damaged.stl: " + says), std::string::npos)
        << repaired.warnings[0];
  }
  return dir.path("damaged.stl");
}

// A patch wound against its neighbours (left by some exporters and repairs) cannot be joined
// to them in a halfedge mesh: read as it came, its seam is split into holes next to the
// defect's rim, reported as non-manifold, and the sample's plan with such a patch at its rim
// agreed with its own at Dice 0.84. load_skull turns the patch back, with a warning, into the
// very mesh the consistent file gives, so that every later stage is the same.
TEST(LoadSkull, APatchWoundAgainstItsNeighboursIsTurnedBack) {
  TempDir dir;
  const Eigen::Vector3d rim = test::head_surface_point(Eigen::Vector3d(0.7, 0.1, 0.7).normalized());
  const SkullMesh head = test::cut_hole(test::make_symmetric_head(4), rim, 25);
  TriangleSoup patched = to_soup(head);
  long long flipped = 0;
  for (auto& t : patched.triangles)
    if (centroid_within(patched, t, rim + Eigen::Vector3d(0, 20, 0), 20.0)) {
      std::swap(t[1], t[2]);
      ++flipped;
    }
  ASSERT_GT(flipped, 20);
  const std::string file = expect_repaired(
      dir, head, patched,
      format_count(flipped) + " triangles in 1 patch wound against their neighbours");
  // Read as it came (plans whose load_skull is version 1 to 4), the seam splits the mesh.
  ExtractBoneSurfaceParams as_it_came;
  as_it_came.orient_consistently = false;
  const LoadedSkull split = load_skull(file, as_it_came);
  EXPECT_GT(split.mesh.n_vertices(), head.n_vertices()) << "the seam's corners doubled";
  bool nonmanifold = false;
  for (const std::string& w : split.warnings)
    nonmanifold |= w.find("non-manifold") != std::string::npos;
  EXPECT_TRUE(nonmanifold);
}

// A patch of the skull written twice, once wound the other way (pieces that overlapped when an
// exporter merged them): the copies are dropped, with a warning, and the mesh is the one the
// file without them gives. Kept, they doubled every crossing there (the sample with its rim's
// patch written twice: rim gap 0.86 mm, Dice 0.86 against its own plan).
TEST(LoadSkull, ATriangleWrittenTwiceIsReadOnce) {
  TempDir dir;
  const Eigen::Vector3d rim = test::head_surface_point(Eigen::Vector3d(0.7, 0.1, 0.7).normalized());
  const SkullMesh head = test::cut_hole(test::make_symmetric_head(4), rim, 25);
  TriangleSoup twice = to_soup(head);
  const size_t n = twice.triangles.size();
  long long copies = 0;
  for (size_t i = 0; i < n; ++i) {
    const Eigen::Vector3i t = twice.triangles[i];
    if (centroid_within(twice, t, rim, 40.0)) {
      twice.triangles.emplace_back(t[0], t[2], t[1]);
      ++copies;
    }
  }
  ASSERT_GT(copies, 20);
  const std::string file = expect_repaired(
      dir, head, twice, format_count(copies) + " triangles repeat another's three corners");
  ExtractBoneSurfaceParams as_it_came;
  as_it_came.drop_repeated_triangles = false;
  EXPECT_EQ(load_skull(file, as_it_came).mesh.n_faces(),
            head.n_faces() + static_cast<size_t>(copies));
}

// Triangles lost here and there (some repairs and decimations leave such holes): a skull's
// surface has no open edge of its own, so each small hole is closed, with a warning, and the
// lines through it tell the bone's inside again. A scan's end or a defect is far longer.
TEST(LoadSkull, SmallHolesAreClosed) {
  TempDir dir;
  const SkullMesh head = test::make_symmetric_head(5);  // triangles about 4 mm across
  TriangleSoup holed = to_soup(head);
  const size_t n = holed.triangles.size();
  // Five triangles lost apart, and two that share one corner (two holes touching there).
  std::vector<size_t> lost;
  for (size_t k = 1; k <= 5; ++k) lost.push_back(k * n / 6);
  auto shared = [&](size_t a, size_t b) {
    int c = 0;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) c += holed.triangles[a][i] == holed.triangles[b][j];
    return c;
  };
  const size_t first = n / 12;
  size_t second = first;
  for (size_t u = 0; u < n && second == first; ++u) {
    bool apart = shared(u, first) == 1;
    for (size_t k : lost) apart &= shared(u, k) == 0 && shared(first, k) == 0;
    if (apart) second = u;
  }
  ASSERT_NE(second, first);
  lost.push_back(first);
  lost.push_back(second);
  std::sort(lost.rbegin(), lost.rend());
  for (size_t k : lost) holed.triangles.erase(holed.triangles.begin() + static_cast<long>(k));
  write_mesh(build_mesh(holed), dir.path("holed.stl"));
  const LoadedSkull closed = load_skull(dir.path("holed.stl"));
  EXPECT_TRUE(report_mesh(closed.mesh).watertight);
  EXPECT_EQ(closed.mesh.n_faces(), head.n_faces());
  ASSERT_FALSE(closed.warnings.empty());
  EXPECT_NE(closed.warnings[0].find("holed.stl: 7 small holes (up to "), std::string::npos)
      << closed.warnings[0];
  // Plans whose load_skull is version 5 left the two that touch at a corner open.
  ExtractBoneSurfaceParams apart_only;
  apart_only.close_holes_through_corners = false;
  const LoadedSkull five = load_skull(dir.path("holed.stl"), apart_only);
  EXPECT_EQ(report_mesh(five.mesh).boundary_edges, 6);
  ExtractBoneSurfaceParams as_it_came;
  as_it_came.close_holes_mm = 0.0;
  const LoadedSkull open = load_skull(dir.path("holed.stl"), as_it_came);
  EXPECT_EQ(report_mesh(open.mesh).boundary_edges, 21);
}

// A skull that 3D Slicer wrote in RAS (SPACE=RAS in the STL's header: how Slicer wrote models
// until 2020, and still does when asked) is read in the patient's LPS: its defect on the
// patient's left lies at +x, as the CT has it, and the load says what it did. Taken as LPS, as
// before such declarations were read, the defect lay on the right (x < 0), and views and
// reports named the sides the wrong way round.
TEST(LoadSkull, ASkullDeclaredRasIsReadInThePatientsFrame) {
  TempDir dir;
  const Eigen::Vector3d left(0.7, 0.1, 0.7);  // +x: the patient's left, in LPS
  const SkullMesh head =
      test::cut_hole(test::make_symmetric_head(4), test::head_surface_point(left.normalized()), 25);
  SkullMesh ras = head;
  for (auto vh : ras.vertices()) {
    ras.point(vh)[0] = -ras.point(vh)[0];
    ras.point(vh)[1] = -ras.point(vh)[1];
  }
  vtkNew<vtkSTLWriter> w;
  w->SetInputData(test::to_polydata(ras));
  w->SetFileName(dir.path("slicer.stl").c_str());
  w->SetFileTypeToBinary();
  w->SetHeader("3D Slicer output. SPACE=RAS");
  w->Write();
  const LoadedSkull s = load_skull(dir.path("slicer.stl"));
  EXPECT_EQ(s.file_space, MeshSpace::RAS);
  const MeshReport r = report_mesh(s.mesh);
  ASSERT_FALSE(r.loops.empty());
  EXPECT_GT(r.loops[0].centroid.x(), 20.0) << "the defect on the patient's left";
  EXPECT_NE(s.frame.find("RAS, as the file declares"), std::string::npos) << s.frame;
  ASSERT_EQ(s.notes.size(), 1u);
  EXPECT_NE(s.notes[0].find("slicer.stl: declares its coordinates RAS (SPACE=RAS"),
            std::string::npos)
      << s.notes[0];
  EXPECT_TRUE(s.warnings.empty() || s.warnings[0].find("RAS") == std::string::npos)
      << "a declaration read is no repair";
  // Plans whose load_skull is version 5 or older took the file's coordinates as LPS.
  ExtractBoneSurfaceParams as_before;
  as_before.mesh_space_from_header = false;
  const LoadedSkull old = load_skull(dir.path("slicer.stl"), as_before);
  EXPECT_EQ(old.file_space, MeshSpace::Undeclared);
  EXPECT_LT(report_mesh(old.mesh).loops[0].centroid.x(), -20.0);
  EXPECT_NE(old.frame.find("the file declares RAS"), std::string::npos) << old.frame;
}

// A CT export may carry the table, a clip or noise far from the head: the skull is its largest
// piece and what lies near it, and the size check sees only that.
TEST(LoadSkull, APieceFarFromTheSkullIsDroppedBeforeTheSizeCheck) {
  test::TempDir dir;
  const SkullMesh head = test::make_symmetric_head(3);
  TriangleSoup soup = to_soup(head);
  const TriangleSoup far = test::box_soup(Eigen::Vector3d(2000, 0, 0), Eigen::Vector3d(2005, 5, 5));
  const TriangleSoup near =
      test::box_soup(Eigen::Vector3d(0, 0, -5), Eigen::Vector3d(3, 3, -2));  // inside the head
  for (const TriangleSoup* piece : {&far, &near}) {
    const int base = static_cast<int>(soup.vertices.size());
    soup.vertices.insert(soup.vertices.end(), piece->vertices.begin(), piece->vertices.end());
    for (const auto& t : piece->triangles)
      soup.triangles.push_back(t + Eigen::Vector3i::Constant(base));
  }
  write_mesh(build_mesh(soup), dir.path("with-table.stl"));
  const LoadedSkull s = load_skull(dir.path("with-table.stl"));
  EXPECT_EQ(s.pieces_dropped, 1);
  EXPECT_EQ(s.mesh.n_faces(), head.n_faces() + near.triangles.size());
  ASSERT_EQ(s.warnings.size(), 1u);
  EXPECT_NE(s.warnings[0].find("1 piece of 12 triangles lying apart from the skull"),
            std::string::npos)
      << s.warnings[0];
  // Plans saved before keep every piece, and so refuse the file as before.
  ExtractBoneSurfaceParams as_before;
  as_before.drop_far_pieces = false;
  EXPECT_THROW(load_skull(dir.path("with-table.stl"), as_before), InputError);
  // Any surface (an implant) keeps its pieces.
  EXPECT_EQ(load_surface(dir.path("with-table.stl")).mesh.n_faces(), soup.triangles.size());
}

}  // namespace
}  // namespace cranioplan
