#include "cranioplan/algorithms/geometry/surface_locator.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <limits>
#include <random>

#include "cranioplan/algorithms/alignment/mirror_mesh.h"
#include "cranioplan/algorithms/alignment/register_icp.h"
#include "cranioplan/model/parallel.h"
#include "support/synthetic.h"

namespace cranioplan {
namespace {

struct Triangle {
  Eigen::Vector3d a, b, c;
};

std::vector<Triangle> triangles(const SkullMesh& mesh) {
  std::vector<Triangle> out;
  for (auto fh : mesh.faces()) {
    const FaceCorners f = face_corners(mesh, fh);
    out.push_back({f.p[0], f.p[1], f.p[2]});
  }
  return out;
}

// Brute force: the distance to a triangle by minimising over a fine barycentric grid is too
// coarse for 1e-9, so the reference is the exact distance to the triangle's plane when the foot
// is inside, else to its three edges.
double distance_to_segment(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                           const Eigen::Vector3d& b) {
  const Eigen::Vector3d ab = b - a;
  const double t = std::clamp((p - a).dot(ab) / ab.squaredNorm(), 0.0, 1.0);
  return (a + t * ab - p).norm();
}

double distance_to_triangle(const Eigen::Vector3d& p, const Triangle& t) {
  const Eigen::Vector3d n = (t.b - t.a).cross(t.c - t.a).normalized();
  const Eigen::Vector3d foot = p - n.dot(p - t.a) * n;
  const auto side = [&](const Eigen::Vector3d& u, const Eigen::Vector3d& v) {
    return (v - u).cross(foot - u).dot(n) >= 0;
  };
  if (side(t.a, t.b) && side(t.b, t.c) && side(t.c, t.a)) return (foot - p).norm();
  return std::min({distance_to_segment(p, t.a, t.b), distance_to_segment(p, t.b, t.c),
                   distance_to_segment(p, t.c, t.a)});
}

// Möller–Trumbore without tolerance: the reference for segments that miss every edge.
std::optional<double> segment_hit(const Eigen::Vector3d& o, const Eigen::Vector3d& d,
                                  const Triangle& t) {
  const Eigen::Vector3d e1 = t.b - t.a, e2 = t.c - t.a, h = d.cross(e2);
  const double det = e1.dot(h);
  if (std::abs(det) < 1e-15) return std::nullopt;
  const Eigen::Vector3d s = o - t.a, q = s.cross(e1);
  const double u = s.dot(h) / det, v = d.dot(q) / det, s_t = e2.dot(q) / det;
  if (u < 0 || v < 0 || u + v > 1 || s_t < 0 || s_t > 1) return std::nullopt;
  return s_t;
}

// A search bounded by a radius gives the unbounded search's distance when the surface is
// nearer, and nothing when it is not (queries near the surface, inside and out, of a moved
// locator too).
TEST(SurfaceLocator, ClosestWithinARadiusAgreesWithTheUnboundedSearch) {
  const SkullMesh head = test::cut_hole(test::make_symmetric_head(3), {40, 20, 50}, 30);
  const SurfaceLocator plain(head);
  const SurfaceLocator moved = plain.moved(RigidTransform{
      Eigen::AngleAxisd(0.3, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix(),
      Eigen::Vector3d(5, -2, 7)});
  std::mt19937 rng(11);
  std::uniform_int_distribution<int> vertex(0, static_cast<int>(head.n_vertices()) - 1);
  std::uniform_real_distribution<double> u(-3.0, 3.0);
  int within = 0, beyond = 0;
  for (const SurfaceLocator* locator : {&plain, &moved}) {
    for (int i = 0; i < 600; ++i) {
      const Eigen::Vector3d on = to_eigen(head.point(SkullMesh::VertexHandle(vertex(rng))));
      const Eigen::Vector3d q = (locator == &plain ? on : moved.closest(on).point) +
                                Eigen::Vector3d(u(rng), u(rng), u(rng));
      const double radius = 0.5 + 0.25 * (i % 9);
      const SurfaceLocator::Closest all = locator->closest(q);
      const auto near = locator->closest_within(q, radius);
      ASSERT_EQ(near.has_value(), all.distance < radius) << i;
      if (!near) {
        ++beyond;
        continue;
      }
      ++within;
      EXPECT_EQ(near->distance, all.distance) << i;
      EXPECT_NEAR((near->point - all.point).norm(), 0.0, 1e-9) << i;
    }
  }
  EXPECT_GT(within, 200);
  EXPECT_GT(beyond, 200);
  EXPECT_EQ(plain.closest_within(Eigen::Vector3d(0, 0, 0), std::numeric_limits<double>::infinity())
                ->distance,
            plain.closest(Eigen::Vector3d(0, 0, 0)).distance);
}

// The faces near a box, found once, answer each query from a point in the box with the very
// distance the tree's search gives (the fit to the bone asks a row of voxels this way), on the
// locator and on the locator moved; a box too far from the surface finds no face.
TEST(SurfaceLocator, FacesNearABoxGiveTheSameDistances) {
  const SkullMesh head = test::cut_hole(test::make_symmetric_head(3), {40, 20, 50}, 30);
  const SurfaceLocator plain(head);
  const SurfaceLocator moved = plain.moved(RigidTransform{
      Eigen::AngleAxisd(0.3, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix(),
      Eigen::Vector3d(5, -2, 7)});
  std::mt19937 rng(12);
  std::uniform_int_distribution<int> vertex(0, static_cast<int>(head.n_vertices()) - 1);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  int within = 0, beyond = 0;
  std::vector<int> faces;
  for (const SurfaceLocator* locator : {&plain, &moved}) {
    for (int row = 0; row < 60; ++row) {
      // A row of 20 points 0.25 mm apart along x near the surface, asked within 0.35 mm.
      const Eigen::Vector3d on = to_eigen(head.point(SkullMesh::VertexHandle(vertex(rng))));
      const Eigen::Vector3d start = (locator == &plain ? on : moved.closest(on).point) +
                                    Eigen::Vector3d(u(rng), u(rng), u(rng));
      const Eigen::Vector3d end = start + Eigen::Vector3d(19 * 0.25, 0, 0);
      const double radius = 0.35;
      locator->faces_near(start, end, radius, faces);
      EXPECT_LT(faces.size(), head.n_faces() / 10) << "a few faces, not the surface";
      for (int i = 0; i < 20; ++i) {
        const Eigen::Vector3d q = start + Eigen::Vector3d(i * 0.25, 0, 0);
        const auto tree = locator->closest_within(q, radius);
        const auto listed = locator->closest_within(q, radius, faces);
        ASSERT_EQ(listed.has_value(), tree.has_value()) << row << " " << i;
        if (!tree) {
          ++beyond;
          continue;
        }
        ++within;
        EXPECT_EQ(listed->distance, tree->distance) << row << " " << i;
        EXPECT_NEAR((listed->point - tree->point).norm(), 0.0, 1e-9);
      }
    }
  }
  EXPECT_GT(within, 200);
  EXPECT_GT(beyond, 200);
  plain.faces_near(Eigen::Vector3d(500, 500, 500), Eigen::Vector3d(501, 500, 500), 1.0, faces);
  EXPECT_TRUE(faces.empty());
}

// A tree large enough to be built on two threads is the tree one thread builds: the same
// faces found for the same queries (ties included), the same bytes.
TEST(SurfaceLocator, TheTreeDoesNotDependOnTheThreads) {
  const SkullMesh head = test::make_symmetric_head(5);
  ASSERT_GT(head.n_faces(), 20000u);
  set_thread_count(1);
  const SurfaceLocator one(head);
  set_thread_count(2);
  const SurfaceLocator two(head);
  set_thread_count(0);
  EXPECT_EQ(one.memory_bytes(), two.memory_bytes());
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-120.0, 120.0);
  for (int i = 0; i < 2000; ++i) {
    const Eigen::Vector3d q(u(rng), u(rng), u(rng)), to(u(rng), u(rng), u(rng));
    const SurfaceLocator::Closest a = one.closest(q), b = two.closest(q);
    ASSERT_EQ(a.face, b.face) << i;
    ASSERT_EQ(a.distance, b.distance) << i;
    const auto ha = one.first_hit(q, to), hb = two.first_hit(q, to);
    ASSERT_EQ(ha.has_value(), hb.has_value()) << i;
    if (ha) {
      ASSERT_EQ(ha->face, hb->face) << i;
    }
  }
}

// Faces deleted but not yet collected are not found; the others are numbered in the order of
// the mesh's face range (which skips deleted ones).
TEST(SurfaceLocator, SkipsDeletedFaces) {
  SkullMesh head = test::make_symmetric_head(4);
  for (int f = 0; f < static_cast<int>(head.n_faces()); f += 3)
    head.delete_face(SkullMesh::FaceHandle(f), false);
  const SurfaceLocator locator(head);
  const std::vector<Triangle> kept = triangles(head);  // the face range's order
  std::mt19937 rng(9);
  std::uniform_real_distribution<double> u(-120.0, 120.0);
  for (int i = 0; i < 300; ++i) {
    const Eigen::Vector3d q(u(rng), u(rng), u(rng));
    double best = std::numeric_limits<double>::infinity();
    for (const auto& t : kept) best = std::min(best, distance_to_triangle(q, t));
    const SurfaceLocator::Closest c = locator.closest(q);
    ASSERT_NEAR(c.distance, best, 1e-9) << i;
    ASSERT_NEAR(distance_to_triangle(c.point, kept[c.face]), 0.0, 1e-9) << i;
  }
}

// Closest points and first hits agree with brute force over every face of an open head (a hole
// cut, so that segments leave through it too) for random queries inside, on and around it.
TEST(SurfaceLocator, AgreesWithBruteForce) {
  const SkullMesh head = test::cut_hole(test::make_symmetric_head(3), {40, 20, 50}, 30);
  const std::vector<Triangle> tris = triangles(head);
  const SurfaceLocator locator(head);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-130.0, 130.0);
  int hits = 0;
  for (int i = 0; i < 400; ++i) {
    const Eigen::Vector3d q(u(rng), u(rng), u(rng));
    double best = std::numeric_limits<double>::infinity();
    for (const auto& t : tris) best = std::min(best, distance_to_triangle(q, t));
    const SurfaceLocator::Closest c = locator.closest(q);
    EXPECT_NEAR(c.distance, best, 1e-9);
    EXPECT_NEAR((c.point - q).norm(), c.distance, 1e-9);
    EXPECT_NEAR(distance_to_triangle(c.point, tris[c.face]), 0.0, 1e-9) << "point on its face";

    const Eigen::Vector3d to(u(rng), u(rng), u(rng));
    std::optional<double> first;
    for (const auto& t : tris)
      if (const auto s = segment_hit(q, to - q, t); s && (!first || *s < *first)) first = s;
    const auto h = locator.first_hit(q, to);
    ASSERT_EQ(h.has_value(), first.has_value()) << "segment " << i;
    if (!h) continue;
    ++hits;
    EXPECT_NEAR(h->distance, *first * (to - q).norm(), 1e-9);
    EXPECT_NEAR(distance_to_triangle(h->point, tris[h->face]), 0.0, 1e-9);
  }
  EXPECT_GT(hits, 100);
}

// A segment through a vertex or along a shared edge still hits the surface.
TEST(SurfaceLocator, SegmentsThroughVerticesAndEdgesHit) {
  const SkullMesh head = test::make_symmetric_head(3);
  const SurfaceLocator locator(head);
  int tried = 0;
  for (auto vh : head.vertices()) {
    if (++tried > 300) break;
    const Eigen::Vector3d p = to_eigen(head.point(vh));
    const auto h = locator.first_hit(Eigen::Vector3d::Zero(), 2.0 * p);
    ASSERT_TRUE(h.has_value()) << "vertex " << vh.idx();
    EXPECT_LT((h->point - p).norm(), 1e-6);
  }
  for (auto eh : head.edges()) {
    if (eh.idx() > 300) break;
    const auto he = head.halfedge_handle(eh, 0);
    const Eigen::Vector3d mid = 0.5 * (to_eigen(head.point(head.from_vertex_handle(he))) +
                                       to_eigen(head.point(head.to_vertex_handle(he))));
    EXPECT_TRUE(locator.first_hit(Eigen::Vector3d::Zero(), 2.0 * mid).has_value());
  }
}

// Every crossing of a segment, in order: through two boxes four, from inside one the odd
// count that says so, along a segment through a vertex or an edge each crossing once.
TEST(SurfaceLocator, HitsAlongASegmentAreEveryCrossingInOrder) {
  TriangleSoup soup = test::box_soup({0, 0, 0}, {10, 10, 10});
  const TriangleSoup second = test::box_soup({20, 0, 0}, {30, 10, 10});
  const int n = static_cast<int>(soup.vertices.size());
  soup.vertices.insert(soup.vertices.end(), second.vertices.begin(), second.vertices.end());
  for (const auto& t : second.triangles) soup.triangles.push_back({t[0] + n, t[1] + n, t[2] + n});
  const SurfaceLocator locator(build_mesh(soup));
  const auto through = locator.hits_along({-5, 3, 4}, {35, 3, 4});
  ASSERT_EQ(through.size(), 4u);
  const double at[] = {0, 10, 20, 30};
  for (size_t k = 0; k < 4; ++k) {
    EXPECT_NEAR(through[k].point.x(), at[k], 1e-9);
    EXPECT_NEAR(through[k].distance, at[k] + 5.0, 1e-9);
  }
  EXPECT_EQ(locator.hits_along({5, 3, 4}, {35, 3, 4}).size() % 2, 1u) << "inside the first";
  EXPECT_EQ(locator.hits_along({15, 3, 4}, {15, 3, 40}).size(), 0u) << "between them";
  EXPECT_EQ(locator.hits_along({-5, -5, -5}, {15, 15, 15}).size(), 2u) << "corner to corner";
  EXPECT_EQ(locator.hits_along({-5, 5, 5}, {-5, 5, 5}).size(), 0u) << "no segment";
}

// The locator of a skull, moved by a reflection and a rigid motion, answers exactly as the
// locator of the mirrored, moved mesh does (a shared tree: nothing copied), with outward normals.
TEST(SurfaceLocator, MovedByAReflectionAnswersForTheMirror) {
  const SkullMesh head = test::cut_hole(test::make_symmetric_head(3), {40, 20, 50}, 30);
  const Plane plane = Plane::through({3, 4, 5}, {1, 0.2, -0.1});
  const RigidTransform motion = RigidTransform::from_axis_angle({0.3, 1, 0.2}, 7.0, {2, -3, 1});
  const SkullMesh mirrored = transform_mesh(mirror_mesh(head, plane), motion);
  const SurfaceLocator own(mirrored);
  const SurfaceLocator original(head);
  const SurfaceLocator moved = original.moved(motion * reflection_across(plane));
  EXPECT_EQ(moved.memory_bytes(), original.memory_bytes());
  const std::vector<Triangle> mirrored_tris = triangles(mirrored);
  int same_face = 0;
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-120.0, 120.0);
  for (int i = 0; i < 200; ++i) {
    const Eigen::Vector3d q(u(rng), u(rng), u(rng)), to(u(rng), u(rng), u(rng));
    const auto a = own.closest(q), b = moved.closest(q);
    EXPECT_NEAR(a.distance, b.distance, 1e-9);
    EXPECT_LT((a.point - b.point).norm(), 1e-6);
    // Where the closest point is a shared vertex or edge either face may be named; the same
    // face (mirror_mesh keeps face order) has the same outward normal.
    EXPECT_NEAR(distance_to_triangle(b.point, mirrored_tris[b.face]), 0.0, 1e-9);
    if (a.face == b.face) {
      ++same_face;
      EXPECT_LT((own.face_normal(a.face) - moved.face_normal(b.face)).norm(), 1e-9);
    }
    const auto ha = own.first_hit(q, to), hb = moved.first_hit(q, to);
    ASSERT_EQ(ha.has_value(), hb.has_value());
    if (ha) {
      EXPECT_NEAR(ha->distance, hb->distance, 1e-9);
    }
  }
  EXPECT_GT(same_face, 100);
  // Outward: the closed head's normals point away from its inside.
  const SkullMesh closed = test::make_symmetric_head(3);
  const SurfaceLocator mirror_of_closed = SurfaceLocator(closed).moved(reflection_across(plane));
  const Eigen::Vector3d inside = plane.reflect(Eigen::Vector3d::Zero());
  for (const Eigen::Vector3d& dir :
       {Eigen::Vector3d(1, 0, 0), Eigen::Vector3d(0, -1, 0), Eigen::Vector3d(0.2, 0.3, 1)}) {
    const auto h = mirror_of_closed.first_hit(inside, inside + 300.0 * dir.normalized());
    ASSERT_TRUE(h.has_value());
    EXPECT_GT(mirror_of_closed.face_normal(h->face).dot(dir.normalized()), 0.0);
  }
}

}  // namespace
}  // namespace cranioplan
