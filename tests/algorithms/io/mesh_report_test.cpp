#include "cranioplan/algorithms/io/mesh_report.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

#include "support/synthetic.h"

namespace cranioplan {
namespace {

TEST(MeshReport, ClosedHeadIsWatertightWithOnePiece) {
  const MeshReport r = report_mesh(test::make_symmetric_head(3));
  EXPECT_TRUE(r.watertight);
  EXPECT_EQ(r.pieces, 1);
  EXPECT_EQ(r.boundary_edges, 0);
  EXPECT_GT(r.volume_mm3, 0);
  EXPECT_EQ(r.triangles, 1280);
}

TEST(MeshReport, HoleGivesBoundaryEdgesAndCubeHasKnownAreaAndVolume) {
  EXPECT_FALSE(
      report_mesh(test::cut_hole(test::make_symmetric_head(3), {70, 0, 0}, 20)).watertight);
  TriangleSoup cube;
  for (int i = 0; i < 8; ++i)
    cube.vertices.emplace_back(i & 1 ? 2 : 0, i & 2 ? 2 : 0, i & 4 ? 2 : 0);
  cube.triangles = {{0, 2, 1}, {1, 2, 3}, {4, 5, 6}, {5, 7, 6}, {0, 1, 4}, {1, 5, 4},
                    {2, 6, 3}, {3, 6, 7}, {0, 4, 2}, {2, 4, 6}, {1, 3, 5}, {3, 7, 5}};
  const MeshReport r = report_mesh(build_mesh(cube));
  EXPECT_NEAR(r.area_mm2, 24.0, 1e-12);
  EXPECT_NEAR(r.volume_mm3, 8.0, 1e-12);
  EXPECT_TRUE(r.watertight);
  EXPECT_EQ(r.bbox_max, Eigen::Vector3d(2, 2, 2));
}

TEST(MeshReport, NonManifoldEdgeIsCounted) {
  TriangleSoup s;
  s.vertices = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}};
  s.triangles = {{0, 1, 2}, {1, 0, 3}, {0, 1, 4}};  // three triangles on edge 0-1
  const MeshReport r = report_mesh(build_mesh(s));
  EXPECT_EQ(r.nonmanifold_edges, 1);
  EXPECT_FALSE(r.watertight);
}

// The flag alone agrees with the full report: closed, holed, non-manifold (three triangles on
// an edge, which the mesh builder splits into vertices at equal positions), two closed pieces.
TEST(MeshReport, IsWatertightAgreesWithTheReport) {
  TriangleSoup fin;
  fin.vertices = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}};
  fin.triangles = {{0, 1, 2}, {1, 0, 3}, {0, 1, 4}};
  TriangleSoup two = to_soup(test::make_symmetric_head(2));
  const size_t n = two.vertices.size(), m = two.triangles.size();
  for (size_t i = 0; i < n; ++i)
    two.vertices.push_back(two.vertices[i] + Eigen::Vector3d(300, 0, 0));
  for (size_t t = 0; t < m; ++t)
    two.triangles.push_back(two.triangles[t] + Eigen::Vector3i::Constant(static_cast<int>(n)));
  // Two closed boxes, each on its own vertices, meeting along an edge (welded, four
  // triangles on it) and at a corner only (welded, every edge still has two).
  const auto boxes = [](const Eigen::Vector3d& shift) {
    TriangleSoup s = test::box_soup({0, 0, 0}, {10, 10, 10});
    const TriangleSoup b = test::box_soup(shift, shift + Eigen::Vector3d(10, 10, 10));
    const int k = static_cast<int>(s.vertices.size());
    s.vertices.insert(s.vertices.end(), b.vertices.begin(), b.vertices.end());
    for (const auto& t : b.triangles) s.triangles.push_back(t + Eigen::Vector3i::Constant(k));
    return build_mesh(s);
  };
  const SkullMesh meshes[] = {test::make_symmetric_head(3),
                              test::cut_hole(test::make_symmetric_head(3), {70, 0, 0}, 20),
                              build_mesh(fin),
                              build_mesh(two),
                              SkullMesh(),
                              boxes({10, 10, 0}),
                              boxes({10, 10, 10})};
  for (const SkullMesh& mesh : meshes)
    EXPECT_EQ(is_watertight(mesh), report_mesh(mesh).watertight) << mesh.n_faces();
  EXPECT_TRUE(is_watertight(meshes[0]));
  EXPECT_TRUE(is_watertight(meshes[3]));
  EXPECT_FALSE(is_watertight(meshes[5])) << "four triangles on the shared edge";
  EXPECT_TRUE(is_watertight(meshes[6])) << "a shared corner";
}

}  // namespace
}  // namespace cranioplan

namespace cranioplan {
namespace {

// A head cut flat across its lower part (where a scan ended) and with a small hole in its side:
// the cut is one loop at the lower border, the hole one loop elsewhere, each measured, and both
// described for a person.
TEST(MeshReport, ACutAtTheBorderAndAHoleAreToldApart) {
  const SkullMesh head = test::make_symmetric_head(5);
  MeshReport whole = report_mesh(head);
  const double cut_z = whole.bbox_min.z() + 30.0;
  SkullMesh cut = test::cut_open(head, Eigen::Vector3d(0, 0, cut_z), Eigen::Vector3d::UnitZ());
  // The cut's vertices put on the cut plane, as marching cubes ends at the scan's last slice.
  for (auto vh : cut.vertices())
    if (cut.is_boundary(vh)) cut.point(vh)[2] = static_cast<float>(cut_z + 0.5);
  const Eigen::Vector3d side((whole.bbox_max.x()), 0.5 * (whole.bbox_min.y() + whole.bbox_max.y()),
                             0.5 * (whole.bbox_min.z() + whole.bbox_max.z()));
  const SkullMesh open = test::cut_hole(cut, side, 6.0);
  const MeshReport r = report_mesh(open);
  ASSERT_EQ(r.loops.size(), 2u);
  EXPECT_TRUE(r.loops[0].at_border);
  EXPECT_EQ(r.loops[0].border, "lower");
  EXPECT_GT(r.loops[0].length_mm, 300.0);  // around a head 140 × 180 mm near its base
  EXPECT_LT(r.loops[0].flatness_mm, 0.1);
  EXPECT_FALSE(r.loops[1].at_border);
  EXPECT_GT(r.loops[1].length_mm, 20.0);  // around a hole of about 12 mm
  EXPECT_LT(r.loops[1].length_mm, 60.0);
  EXPECT_LT((r.loops[1].centroid - side).norm(), 8.0);
  const std::vector<std::string> said = describe_openings(r);
  ASSERT_EQ(said.size(), 2u);
  EXPECT_EQ(said[0].rfind("open along a flat cut at its lower border (z = ", 0), 0u) << said[0];
  EXPECT_NE(said[0].find("1 loop, "), std::string::npos) << said[0];
  EXPECT_EQ(said[1].rfind("1 hole in the surface", 0), 0u) << said[1];
  EXPECT_TRUE(describe_openings(whole).empty());
}

// The thick head as an importer that pads the volume meshes a scan that ended 30 mm above its
// lowest point: closed, with a flat cap across the bone at the lower border, found and
// described; the whole head has none (its lowest part is curved, not flat).
TEST(MeshReport, AScanEndClosedByPaddingIsACap) {
  const SkullMesh head = test::make_thick_head(0.93, 1.0);
  const MeshReport whole = report_mesh(head);
  EXPECT_TRUE(whole.caps.empty());
  EXPECT_TRUE(describe_caps(whole).empty());
  const double cut_z = whole.bbox_min.z() + 30.0;
  const SkullMesh padded =
      test::scanned_padded(head, Eigen::Vector3d(0, 0, cut_z), Eigen::Vector3d::UnitZ());
  const MeshReport r = report_mesh(padded);
  EXPECT_TRUE(r.watertight);
  ASSERT_EQ(r.caps.size(), 1u);
  const BorderCap& cap = r.caps[0];
  EXPECT_EQ(cap.border, "lower");
  EXPECT_EQ(cap.outward, -Eigen::Vector3d::UnitZ());
  EXPECT_NEAR(cap.centroid.z(), cut_z, 1.0);
  // The ring of bone the cut crosses: about its length (400-500 mm) times the bone's 5-6 mm.
  EXPECT_GT(cap.area_mm2, 1500.0);
  EXPECT_LT(cap.area_mm2, 4000.0);
  EXPECT_TRUE(describe_openings(r).empty()) << "closed: no opening to repair";
  const std::vector<std::string> said = describe_caps(r);
  ASSERT_EQ(said.size(), 1u);
  EXPECT_EQ(said[0].rfind("closed by a flat cap at its lower border (z = ", 0), 0u) << said[0];
}

// A cut across solid bone (a field of view that shaves the side of the head, as on the sample)
// is flat and at the end, but covers its whole outline and rings no opening: not a cap.
TEST(MeshReport, ACutAcrossSolidBoneIsNotACap) {
  const SkullMesh solid = test::make_symmetric_head(5);
  const MeshReport whole = report_mesh(solid);
  const double cut_z = whole.bbox_min.z() + 30.0;
  const MeshReport r = report_mesh(
      test::scanned_padded(solid, Eigen::Vector3d(0, 0, cut_z), Eigen::Vector3d::UnitZ()));
  EXPECT_TRUE(r.watertight);
  EXPECT_TRUE(r.caps.empty()) << r.caps.size() << " caps, the first " << r.caps[0].area_mm2
                              << " mm²";
}

// The same head cut along a plane tilted 30° from the axial (a tilted gantry, or a skull that
// came in turned): the cut is still the lower border, its outward normal the plane's.
TEST(MeshReport, AnObliqueCutAtTheBorderIsFoundInItsOwnPlane) {
  const SkullMesh head = test::make_symmetric_head(5);
  const MeshReport whole = report_mesh(head);
  const Eigen::Vector3d up(0.0, std::sin(M_PI / 6), std::cos(M_PI / 6));
  const Eigen::Vector3d through(0, 0, whole.bbox_min.z() + 45.0);
  SkullMesh cut = test::cut_open(head, through, up);
  for (auto vh : cut.vertices())
    if (cut.is_boundary(vh)) {
      const Eigen::Vector3d p = to_eigen(cut.point(vh));
      cut.set_point(vh, to_point(p - (p - through).dot(up) * up + 0.5 * up));
    }
  const MeshReport r = report_mesh(cut);
  ASSERT_EQ(r.loops.size(), 1u);
  EXPECT_TRUE(r.loops[0].at_border);
  EXPECT_EQ(r.loops[0].border, "lower");
  EXPECT_LT(std::acos(std::clamp(-r.loops[0].outward.dot(up), -1.0, 1.0)), 1e-3);
  // Its outline: convex, counter-clockwise about the outward normal, around every vertex of the
  // cut (seen along the normal), its corners in the cut's plane.
  const std::vector<Eigen::Vector3d>& outline = r.loops[0].outline;
  ASSERT_GE(outline.size(), 3u);
  for (const Eigen::Vector3d& c : outline) EXPECT_NEAR((c - through).dot(up), 0.5, 1e-3);
  int inside = 0;
  for (auto vh : cut.vertices()) {
    if (!cut.is_boundary(vh)) continue;
    const Eigen::Vector3d p = to_eigen(cut.point(vh));
    bool within = true;
    for (size_t i = 0; i < outline.size(); ++i) {
      const Eigen::Vector3d& a = outline[i];
      const Eigen::Vector3d& b = outline[(i + 1) % outline.size()];
      within = within && (b - a).cross(p - a).dot(r.loops[0].outward) >= -1e-6;
    }
    inside += within;
  }
  EXPECT_EQ(inside, r.loops[0].edges);  // a closed loop has as many vertices as edges
  const std::vector<std::string> said = describe_openings(r);
  ASSERT_EQ(said.size(), 1u);
  EXPECT_EQ(
      said[0].rfind("open along a flat cut at its lower border (a plane tilted 30° from z", 0), 0u)
      << said[0];
}

// Bone the scan's cut crosses besides the vault (an island in the orbits, the nose) leaves small
// loops in the cut's plane: they are the same cut, not holes.
TEST(MeshReport, SmallLoopsInTheCutsPlaneArePartOfTheCut) {
  const SkullMesh head = test::make_symmetric_head(5);
  const MeshReport whole = report_mesh(head);
  const double cut_z = whole.bbox_min.z() + 30.0;
  const Eigen::Vector3d up = Eigen::Vector3d::UnitZ();
  TriangleSoup s = to_soup(test::cut_open(head, Eigen::Vector3d(0, 0, cut_z), up));
  // A 10 × 10 mm bar below the head's middle, cut by the same plane: a loop of 40 mm.
  const Eigen::Vector3d mid = 0.5 * (whole.bbox_min + whole.bbox_max);
  const TriangleSoup bar = to_soup(
      test::cut_open(test::mask_meshed_box(Eigen::Vector3d(mid.x() - 5, mid.y() - 5, cut_z - 10),
                                           Eigen::Vector3d(mid.x() + 5, mid.y() + 5, cut_z + 20)),
                     Eigen::Vector3d(0, 0, cut_z), up));
  const int base = static_cast<int>(s.vertices.size());
  s.vertices.insert(s.vertices.end(), bar.vertices.begin(), bar.vertices.end());
  for (const auto& t : bar.triangles) s.triangles.push_back(t + Eigen::Vector3i::Constant(base));
  const MeshReport r = report_mesh(build_mesh(s));
  ASSERT_EQ(r.loops.size(), 2u);
  EXPECT_LT(r.loops[1].length_mm, 50.0) << "the bar's loop";
  for (const BoundaryLoop& l : r.loops) {
    EXPECT_TRUE(l.at_border);
    EXPECT_EQ(l.border, "lower");
  }
  const std::vector<std::string> said = describe_openings(r);
  ASSERT_EQ(said.size(), 1u) << "no holes";
  EXPECT_NE(said[0].find("2 loops, "), std::string::npos) << said[0];
}

// A slot 3 mm wide through the right half of the head: its loop is flat and long, but the head
// goes on on both sides of its plane, so it is a hole, not where a scan ended.
TEST(MeshReport, AFlatLoopWithTheMeshOnBothSidesIsAHole) {
  TriangleSoup s = to_soup(test::make_symmetric_head(5));
  std::vector<Eigen::Vector3i> kept;
  for (const auto& t : s.triangles) {
    const Eigen::Vector3d c = (s.vertices[t[0]] + s.vertices[t[1]] + s.vertices[t[2]]) / 3.0;
    if (!(c.x() < -5.0 && std::abs(c.z() - 20.0) < 1.5)) kept.push_back(t);
  }
  s.triangles = kept;
  const MeshReport r = report_mesh(build_mesh(s));
  ASSERT_EQ(r.loops.size(), 1u);
  EXPECT_GT(r.loops[0].length_mm, 200.0);
  EXPECT_LE(r.loops[0].flatness_mm, 0.01 * r.loops[0].length_mm) << "flat enough for a cut";
  EXPECT_FALSE(r.loops[0].at_border);
  EXPECT_EQ(r.loops[0].outward, Eigen::Vector3d::Zero());
}

}  // namespace
}  // namespace cranioplan
