#include "cranioplan/model/mesh.h"

#include <gtest/gtest.h>

#include <algorithm>

#include "support/synthetic.h"

namespace cranioplan {
namespace {

TEST(Mesh, BuildDropsDegenerateTrianglesAndCountsThem) {
  TriangleSoup s;
  s.vertices = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {2, 0, 0}};
  s.triangles = {{0, 1, 2}, {0, 1, 3}, {0, 0, 2}};  // second collinear, third repeated index
  BuildMeshStats stats;
  const SkullMesh m = build_mesh(s, &stats);
  EXPECT_EQ(m.n_faces(), 1u);
  EXPECT_EQ(m.n_vertices(), 3u);
  EXPECT_EQ(stats.degenerate_dropped, 2);
}

// The canonical form depends only on the triangles: the same surface listed with its vertices
// in another order, a position given twice (as an STL has it once per triangle), triangles
// starting at another corner and in another order all give the same soup; orientation is kept.
TEST(Mesh, CanonicalFormDependsOnlyOnTheTriangles) {
  TriangleSoup a = to_soup(test::make_symmetric_head(2));
  TriangleSoup b;
  const int n = static_cast<int>(a.vertices.size());
  std::vector<int> where(n);
  for (int i = 0; i < n; ++i) {
    where[i] = (i * 7919) % n;  // 7919 is prime and does not divide n: a permutation
    ASSERT_LT(where[i], n);
  }
  b.vertices.resize(n);
  for (int i = 0; i < n; ++i) b.vertices[where[i]] = a.vertices[i];
  b.vertices.push_back(b.vertices[where[0]]);  // vertex 0 given twice
  for (size_t k = 0; k < a.triangles.size(); ++k) {
    const Eigen::Vector3i& t = a.triangles[a.triangles.size() - 1 - k];  // reversed order
    Eigen::Vector3i u(where[t[1]], where[t[2]], where[t[0]]);            // another first corner
    for (int c = 0; c < 3; ++c)
      if (t[c] == 0 && k % 2 == 0) u[(c + 2) % 3] = n;  // half of them use the duplicate
    b.triangles.push_back(u);
  }
  make_canonical(a);
  make_canonical(b);
  EXPECT_EQ(a.vertices, b.vertices);
  EXPECT_EQ(a.triangles, b.triangles);
  EXPECT_GT(signed_volume(a), 0.0);
  EXPECT_DOUBLE_EQ(signed_volume(a), signed_volume(b));
  EXPECT_TRUE(std::is_sorted(
      a.vertices.begin(), a.vertices.end(), [](const Eigen::Vector3d& p, const Eigen::Vector3d& q) {
        return std::lexicographical_compare(p.data(), p.data() + 3, q.data(), q.data() + 3);
      }));
}

// Built in place (OpenMesh meshes cannot be moved), a mesh is the one build_mesh returns,
// whatever the mesh held before.
TEST(Mesh, BuildingInPlaceGivesTheSameMeshWhateverItHeld) {
  const TriangleSoup soup = to_soup(test::make_symmetric_head(2));
  const SkullMesh fresh = build_mesh(soup);
  SkullMesh reused = test::make_symmetric_head(3);
  BuildMeshStats stats;
  build_mesh(soup, reused, &stats);
  EXPECT_EQ(stats.degenerate_dropped, 0);
  const TriangleSoup a = to_soup(fresh), b = to_soup(reused);
  EXPECT_EQ(a.vertices, b.vertices);
  EXPECT_EQ(a.triangles, b.triangles);
  EXPECT_EQ(reused.n_edges(), fresh.n_edges());
  for (auto he : reused.halfedges())
    EXPECT_EQ(reused.to_vertex_handle(reused.next_halfedge_handle(he)),
              fresh.to_vertex_handle(fresh.next_halfedge_handle(he)));
}

TEST(Mesh, SignedVolumeOfHeadIsPositiveAndFlipNegates) {
  SkullMesh head = test::make_symmetric_head(3);
  const double v = signed_volume(head);
  EXPECT_GT(v, 0.0);
  flip_orientation(head);
  EXPECT_NEAR(signed_volume(head), -v, 1e-6 * v);
}

}  // namespace
}  // namespace cranioplan
