#include <gtest/gtest.h>

#include <algorithm>

#include "cranioplan/model/error.h"
#include "cranioplan/model/marker.h"
#include "cranioplan/model/mesh.h"
#include "cranioplan/model/plane.h"
#include "cranioplan/model/rigid_transform.h"
#include "support/synthetic.h"

namespace cranioplan {

TEST(Plane, ReflectIsAnInvolutionAndFixesThePlane) {
  const Plane p = Plane::through({1, 2, 3}, {1, 1, 0});
  const Eigen::Vector3d x(4, -5, 6);
  EXPECT_LT((p.reflect(p.reflect(x)) - x).norm(), 1e-12);
  EXPECT_NEAR(p.signed_distance(p.reflect(x)), -p.signed_distance(x), 1e-12);
  const Eigen::Vector3d on = p.project(x);
  EXPECT_LT((p.reflect(on) - on).norm(), 1e-12);
  EXPECT_NEAR(p.angle_to_deg(p.flipped()), 0.0, 1e-9);
}

// Angles around an axis start from a direction given by the caller (anatomy, a marker), not
// from the coordinate axes; along the axis there is none, and any unit vector across will do.
TEST(Plane, UnitAcrossAnAxisDropsThePartAlongIt) {
  const Eigen::Vector3d axis = Eigen::Vector3d(1, 2, 2) / 3.0;
  const Eigen::Vector3d e = unit_across(Eigen::Vector3d(3, 0, 0), axis);
  EXPECT_NEAR(e.norm(), 1.0, 1e-12);
  EXPECT_NEAR(e.dot(axis), 0.0, 1e-12);
  EXPECT_NEAR(e.dot(Eigen::Vector3d(8, -2, -2).normalized()), 1.0, 1e-12);  // (3,0,0) − 1·(1,2,2)
  const Eigen::Vector3d any = unit_across(-2.0 * axis, axis);
  EXPECT_NEAR(any.norm(), 1.0, 1e-12);
  EXPECT_NEAR(any.dot(axis), 0.0, 1e-12);
}

TEST(RigidTransform, InverseAndComposition) {
  const RigidTransform t = RigidTransform::from_axis_angle({1, 2, 3}, 30, {4, 5, 6});
  const Eigen::Vector3d x(1, -1, 2);
  EXPECT_LT(((t.inverse() * t).apply(x) - x).norm(), 1e-12);
  EXPECT_NEAR(t.rotation_angle_deg(), 30.0, 1e-9);
}

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

TEST(Mesh, SignedVolumeOfHeadIsPositiveAndFlipNegates) {
  SkullMesh head = test::make_symmetric_head(3);
  const double v = signed_volume(head);
  EXPECT_GT(v, 0.0);
  flip_orientation(head);
  EXPECT_NEAR(signed_volume(head), -v, 1e-6 * v);
}

TEST(Error, InputErrorNamesFileFirstAndCountsReadably) {
  const InputError e("skull.stl", "file ends after 1,203 of 40,000 triangles");
  EXPECT_STREQ(e.what(), "skull.stl: file ends after 1,203 of 40,000 triangles");
  EXPECT_EQ(format_count(40000), "40,000");
  EXPECT_EQ(format_count(-1234567), "-1,234,567");
  EXPECT_EQ(format_count(999), "999");
}

}  // namespace cranioplan

namespace cranioplan {
namespace {

TEST(Markers, EdgeMarkerCentreAveragesOnlyEdgeMarkers) {
  EXPECT_FALSE(edge_marker_centre({}).has_value());
  const std::vector<Marker> markers = {
      {1, MarkerType::OuterEdge, {0, 0, 0}, MarkerSurface::Original},
      {2, MarkerType::InnerEdge, {4, 2, 0}, MarkerSurface::Original},
      {3, MarkerType::OuterSurface, {100, 100, 100}, MarkerSurface::Mirrored}};
  const auto c = edge_marker_centre(markers);
  ASSERT_TRUE(c.has_value());
  EXPECT_TRUE(c->isApprox(Eigen::Vector3d(2, 1, 0)));
  EXPECT_FALSE(edge_marker_centre({markers[2]}).has_value()) << "surface markers only";
}

}  // namespace
}  // namespace cranioplan
