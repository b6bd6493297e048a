#include "cranioplan/algorithms/alignment/mirror_mesh.h"

#include <gtest/gtest.h>

#include "cranioplan/algorithms/geometry/point_index.h"
#include "support/synthetic.h"

namespace cranioplan {
namespace {

TEST(MirrorMesh, KeepsVolumePositiveAndMapsThePlaneOntoItself) {
  const SkullMesh head = test::cut_hole(test::make_symmetric_head(4), {50, 10, 30}, 25);
  const Plane plane = Plane::through({3, 4, 5}, {1, 0.2, -0.1});
  const SkullMesh m = mirror_mesh(head, plane);
  EXPECT_EQ(m.n_vertices(), head.n_vertices());
  EXPECT_EQ(m.n_faces(), head.n_faces());
  EXPECT_GT(signed_volume(m), 0.0);
  // A closed mesh keeps its volume exactly (an open one's signed volume depends on the origin).
  const SkullMesh closed = test::make_symmetric_head(4);
  EXPECT_NEAR(signed_volume(mirror_mesh(closed, plane)), signed_volume(closed),
              1e-9 * signed_volume(closed));
  for (auto vh : head.vertices()) {
    const Eigen::Vector3d p = to_eigen(head.point(vh)), q = to_eigen(m.point(vh));
    EXPECT_NEAR(plane.signed_distance(q), -plane.signed_distance(p), 1e-9);
    EXPECT_LT((plane.project(p) - plane.project(q)).norm(), 1e-9);  // same foot on the plane
  }
  const SkullMesh back = mirror_mesh(m, plane);
  for (auto vh : head.vertices())
    EXPECT_LT((to_eigen(back.point(vh)) - to_eigen(head.point(vh))).norm(), 1e-9);
}

TEST(MirrorMesh, SymmetricHeadMirrorsOntoItself) {
  const SkullMesh head = test::make_symmetric_head(4);
  const SkullMesh m = mirror_mesh(head, Plane{Eigen::Vector3d::UnitX(), 0});
  std::vector<Eigen::Vector3d> pts;
  for (auto vh : head.vertices()) pts.push_back(to_eigen(head.point(vh)));
  const PointIndex index(pts);
  for (auto vh : m.vertices()) {
    double d2;
    index.nearest(to_eigen(m.point(vh)), &d2);
    EXPECT_LT(d2, 1e-18);
  }
}

}  // namespace
}  // namespace cranioplan
