#include "cranioplan/model/mesh.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "cranioplan/model/parallel.h"
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

// A face's corners in its order, and their cross product: along the outward normal, twice the
// area long.
TEST(Mesh, FaceCornersAreInTheFacesOrder) {
  TriangleSoup s;
  s.vertices = {{5, 0, 0}, {0, 0, 1}, {3, 0, 0}, {3, 4, 0}};
  s.triangles = {{2, 0, 3}};  // vertex 1 unused
  const SkullMesh m = build_mesh(s);
  ASSERT_EQ(m.n_faces(), 1u);
  const FaceCorners f = face_corners(m, *m.faces().begin());
  // The triangle's order (from whichever corner the face starts), each id its point's.
  const Eigen::Vector3d want[3] = {{3, 0, 0}, {5, 0, 0}, {3, 4, 0}};
  const int first = static_cast<int>(std::find(f.p.begin(), f.p.end(), want[0]) - f.p.begin());
  ASSERT_LT(first, 3);
  for (int k = 0; k < 3; ++k) {
    EXPECT_EQ(f.p[(first + k) % 3], want[k]) << k;
    EXPECT_EQ(to_eigen(m.point(SkullMesh::VertexHandle(f.ids[k]))), f.p[k]) << k;
  }
  EXPECT_EQ(f.cross(), Eigen::Vector3d(0, 0, 8));  // 2 × 4 mm, area 4 mm²
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

// Known answer: the surface of a box (two triangles a side) has its centroid at the box's
// centre, and keeps it when one side is split into many more triangles, while the vertices'
// mean moves towards that side. An open surface too: a lone triangle's is its centroid.
TEST(Mesh, SurfaceCentroidIsTheSameHoweverTheSurfaceIsTriangulated) {
  TriangleSoup box;
  box.vertices = {{0, 0, 0}, {4, 0, 0}, {4, 2, 0}, {0, 2, 0},
                  {0, 0, 6}, {4, 0, 6}, {4, 2, 6}, {0, 2, 6}};
  box.triangles = {{0, 2, 1}, {0, 3, 2}, {4, 5, 6}, {4, 6, 7}, {0, 1, 5}, {0, 5, 4},
                   {1, 2, 6}, {1, 6, 5}, {2, 3, 7}, {2, 7, 6}, {3, 0, 4}, {3, 4, 7}};
  SkullMesh mesh = build_mesh(box);
  const Eigen::Vector3d centre(2, 1, 3);
  EXPECT_LT((surface_centroid(mesh) - centre).norm(), 1e-12);
  EXPECT_LT((vertex_centroid(mesh) - centre).norm(), 1e-12);
  // The side z = 6 split at its faces' centroids, four times over (2 faces to 162).
  for (int round = 0; round < 4; ++round) {
    std::vector<SkullMesh::FaceHandle> top;
    for (auto fh : mesh.faces()) {
      bool on_top = true;
      for (auto vh : mesh.fv_range(fh)) on_top = on_top && mesh.point(vh)[2] == 6.0;
      if (on_top) top.push_back(fh);
    }
    for (auto fh : top) {
      const FaceCorners f = face_corners(mesh, fh);
      mesh.split(fh, to_point((f.p[0] + f.p[1] + f.p[2]) / 3.0));
    }
  }
  ASSERT_EQ(mesh.n_faces(), 10u + 162u);
  EXPECT_LT((surface_centroid(mesh) - centre).norm(), 1e-9);
  EXPECT_GT(vertex_centroid(mesh).z() - centre.z(), 2.0);
  TriangleSoup one;
  one.vertices = {{0, 0, 0}, {3, 0, 0}, {0, 3, 3}};
  one.triangles = {{0, 1, 2}};
  EXPECT_LT((surface_centroid(build_mesh(one)) - Eigen::Vector3d(1, 1, 1)).norm(), 1e-12);
  EXPECT_EQ(surface_centroid(SkullMesh()), Eigen::Vector3d::Zero());
}

// Coordinates are rounded as a conversion to float rounds (to nearest, ties to even), also at
// exact ties, where a carry reaches the next power of two, for negative numbers and zeros.
TEST(Mesh, CanonicalCoordinatesAreRoundedAsAFloatConversionRounds) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> coordinate(-400.0, 400.0);
  std::vector<double> xs = {0.0, -0.0, 1.0, -1.0, std::nextafter(2.0, 0.0), 0.1, -0.1};
  for (int i = 0; i < 3000; ++i) {
    const double x = coordinate(rng);
    const float f = static_cast<float>(x);
    const double mid = (static_cast<double>(f) + std::nextafter(f, 1e9f)) / 2.0;  // a tie
    xs.insert(xs.end(), {x, mid, -mid, std::nextafter(mid, 1e9), std::nextafter(mid, -1e9)});
  }
  TriangleSoup soup;
  for (double x : xs) {
    soup.vertices.push_back({x, 1.0, 2.0});
    soup.vertices.push_back({x, 3.0, 2.0});
    soup.vertices.push_back({x, 1.0, 5.0});
    const int n = static_cast<int>(soup.vertices.size());
    soup.triangles.push_back({n - 3, n - 2, n - 1});
  }
  std::vector<double> expected;
  for (double x : xs) {
    volatile float f = static_cast<float>(x);  // volatile: the round trip is not optimised away
    expected.push_back(static_cast<double>(f) == 0.0 ? 0.0 : static_cast<double>(f));
  }
  std::sort(expected.begin(), expected.end());
  expected.erase(std::unique(expected.begin(), expected.end()), expected.end());
  make_canonical(soup);
  std::vector<double> got;
  for (const Eigen::Vector3d& v : soup.vertices)
    if (got.empty() || got.back() != v.x()) got.push_back(v.x());
  ASSERT_EQ(got.size(), expected.size());
  for (size_t i = 0; i < got.size(); ++i) {
    EXPECT_EQ(got[i], expected[i]) << i;
    EXPECT_FALSE(std::signbit(got[i]) && got[i] == 0.0);  // −0 is +0
  }
}

// A soup as files give them, damaged: triangles flipped against their neighbours, given
// twice, fins on an edge (three faces on it), two surfaces touching at one vertex, zero-area
// triangles. build_mesh keeps every triangle with area and gives the same halfedges on one
// thread and on two.
TEST(Mesh, ADamagedSoupIsBuiltTheSameOnOneThreadAndOnTwo) {
  TriangleSoup soup = to_soup(test::make_symmetric_head(3));
  const int nv = static_cast<int>(soup.vertices.size());
  const size_t nt = soup.triangles.size();
  std::mt19937 rng(3);
  size_t degenerate = 0;
  for (size_t i = 0; i < nt; ++i) {
    Eigen::Vector3i t = soup.triangles[i];
    switch (rng() % 50) {
      case 0:
        std::swap(soup.triangles[i][1], soup.triangles[i][2]);
        break;
      case 1:
        soup.triangles.push_back(t);
        break;
      case 2:
        t[2] = static_cast<int>(rng() % static_cast<unsigned>(nv));
        soup.triangles.push_back(t);
        break;
      case 3:
        t[1] = t[0];
        soup.triangles.push_back(t);
        ++degenerate;
        break;
      default:
        break;
    }
  }
  // A second copy of the head, moved so that its vertex 0 lies on the first one's vertex 0.
  const size_t first_faces = soup.triangles.size();
  for (size_t i = 0; i < nt; ++i) {
    Eigen::Vector3i t = soup.triangles[i];
    for (int k = 0; k < 3; ++k) t[k] = t[k] == 0 ? 0 : t[k] + nv;
    soup.triangles.push_back(t);
  }
  for (int v = 0; v < nv; ++v)
    soup.vertices.push_back(soup.vertices[v] + 2.0 * (soup.vertices[v] - soup.vertices[0]));
  std::shuffle(soup.triangles.begin(), soup.triangles.end(), rng);

  SkullMesh built[2];
  BuildMeshStats stats[2];
  for (int threads : {1, 2}) {
    set_thread_count(threads);
    build_mesh(soup, built[threads - 1], &stats[threads - 1]);
  }
  set_thread_count(0);
  const SkullMesh &a = built[0], &b = built[1];
  // (A fin's random corner may repeat one of its others: one more without area.)
  EXPECT_GE(stats[0].degenerate_dropped, static_cast<long long>(degenerate));
  EXPECT_GT(stats[0].nonmanifold_split, 0);
  EXPECT_EQ(stats[0].degenerate_dropped, stats[1].degenerate_dropped);
  EXPECT_EQ(stats[0].nonmanifold_split, stats[1].nonmanifold_split);
  EXPECT_EQ(a.n_faces(), soup.triangles.size() - static_cast<size_t>(stats[0].degenerate_dropped));
  EXPECT_GT(soup.triangles.size(), first_faces);
  ASSERT_EQ(a.n_vertices(), b.n_vertices());
  ASSERT_EQ(a.n_edges(), b.n_edges());
  ASSERT_EQ(a.n_faces(), b.n_faces());
  for (auto v : a.vertices()) {
    ASSERT_EQ(a.point(v), b.point(v)) << v.idx();
    ASSERT_EQ(a.halfedge_handle(v), b.halfedge_handle(v)) << v.idx();
  }
  for (auto h : a.halfedges()) {
    ASSERT_EQ(a.to_vertex_handle(h), b.to_vertex_handle(h)) << h.idx();
    ASSERT_EQ(a.next_halfedge_handle(h), b.next_halfedge_handle(h)) << h.idx();
    ASSERT_EQ(a.prev_halfedge_handle(h), b.prev_halfedge_handle(h)) << h.idx();
    ASSERT_EQ(a.face_handle(h), b.face_handle(h)) << h.idx();
    // A consistent halfedge structure: next and prev invert each other, twins run back.
    ASSERT_EQ(a.prev_halfedge_handle(a.next_halfedge_handle(h)), h) << h.idx();
    ASSERT_EQ(a.from_vertex_handle(a.opposite_halfedge_handle(h)), a.to_vertex_handle(h));
  }
  for (auto f : a.faces()) ASSERT_EQ(a.halfedge_handle(f), b.halfedge_handle(f)) << f.idx();
}

// Vertices of very high valence (a pole, a cap triangulated as a fan) are searched by sorting:
// a closed cone of 500 sides (two poles of 500 triangles) is built closed and manifold; two
// such cones touching at one pole give that pole a copy; a third of the triangles given twice
// are kept on their own vertices, one split each.
TEST(Mesh, PolesOfHundredsOfTrianglesAreBuiltWhole) {
  const int n = 500;
  auto cone = [&](TriangleSoup& s, const Eigen::Vector3d& apex, double z) {
    const int a = static_cast<int>(s.vertices.size());
    s.vertices.push_back(apex);
    s.vertices.push_back({0, 0, z});
    for (int i = 0; i < n; ++i) {
      const double t = 2 * M_PI * i / n;
      s.vertices.push_back({40 * std::cos(t), 40 * std::sin(t), z + 0.3 * std::sin(5 * t)});
    }
    for (int i = 0; i < n; ++i) {
      const int p = a + 2 + i, q = a + 2 + (i + 1) % n;
      s.triangles.push_back({a, p, q});
      s.triangles.push_back({a + 1, q, p});
    }
  };
  TriangleSoup one;
  cone(one, {0, 0, 30}, 0);
  const SkullMesh m = build_mesh(one);
  EXPECT_EQ(m.n_faces(), 2u * n);
  EXPECT_EQ(m.n_vertices(), static_cast<size_t>(n) + 2);
  EXPECT_EQ(m.n_edges(), 3u * n);
  for (auto h : m.halfedges()) EXPECT_FALSE(m.is_boundary(h));

  TriangleSoup two = one;  // a second cone, upside down, its apex on the first one's
  cone(two, {0, 0, 30}, 60);
  const int second = static_cast<int>(one.vertices.size());
  for (size_t t = one.triangles.size(); t < two.triangles.size(); ++t) {
    for (int k = 0; k < 3; ++k)
      if (two.triangles[t][k] == second) two.triangles[t][k] = 0;
    std::swap(two.triangles[t][1], two.triangles[t][2]);  // outward on the upside-down cone
  }
  TriangleSoup twice = two;
  for (size_t t = 0; t < one.triangles.size(); t += 3) twice.triangles.push_back(one.triangles[t]);
  for (int threads : {1, 2}) {
    set_thread_count(threads);
    BuildMeshStats stats;
    const SkullMesh touching = build_mesh(two, &stats);
    EXPECT_EQ(stats.nonmanifold_split, 1) << "the shared pole, once";
    EXPECT_EQ(touching.n_faces(), 4u * n);
    for (auto h : touching.halfedges()) EXPECT_FALSE(touching.is_boundary(h));
    BuildMeshStats more;
    const SkullMesh doubled = build_mesh(twice, &more);
    const long long repeated =
        static_cast<long long>(twice.triangles.size() - two.triangles.size());
    EXPECT_EQ(doubled.n_faces(), twice.triangles.size());
    EXPECT_EQ(more.nonmanifold_split, 1 + repeated);
  }
  set_thread_count(0);
}

}  // namespace
}  // namespace cranioplan
