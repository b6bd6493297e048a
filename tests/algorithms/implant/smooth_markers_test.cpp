#include "cranioplan/algorithms/implant/smooth_markers.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>

#include "cranioplan/algorithms/geometry/surface_locator.h"
#include "support/synthetic.h"

namespace cranioplan {
namespace {

Marker mk(int id, MarkerType t, double x, double y, double z) {
  return {id, t, Eigen::Vector3d(x, y, z), default_surface(t)};
}

TEST(SmoothMarkers, HandComputedWeightedMeanWithFixedEdges) {
  // Outer layer: two edge markers and one surface marker; an inner marker far away.
  const std::vector<Marker> in = {
      mk(1, MarkerType::OuterEdge, 0, 0, 0), mk(2, MarkerType::OuterEdge, 4, 0, 0),
      mk(3, MarkerType::OuterSurface, 2, 3, 0), mk(4, MarkerType::InnerSurface, 2, 3, 1)};
  SmoothParams p;
  p.radius_mm = 5.0;
  p.edge_weight = 2.0;
  const SmoothResult r = smooth_markers(in, p);
  ASSERT_EQ(r.status, SmoothResult::Status::Smoothed);
  // (1·(2,3,0) + 2·(0,0,0) + 2·(4,0,0)) / 5 = (2, 0.6, 0)
  EXPECT_LT((r.markers[2].position - Eigen::Vector3d(2, 0.6, 0)).norm(), 1e-12);
  EXPECT_EQ(r.markers[0].position, in[0].position);  // edges never move
  EXPECT_EQ(r.markers[1].position, in[1].position);
  // The inner marker has no inner neighbours (the outer ones are another layer): unchanged.
  EXPECT_EQ(r.markers[3].position, in[3].position);
  EXPECT_NEAR(r.max_move_mm, 2.4, 1e-12);
}

TEST(SmoothMarkers, RadiusCutOffIsInclusiveAndExcludesCoincidentPoints) {
  const std::vector<Marker> in = {
      mk(1, MarkerType::OuterSurface, 0, 0, 0),
      mk(2, MarkerType::OuterSurface, 3, 0, 0),  // exactly at radius
      mk(3, MarkerType::OuterSurface, 3.001, 0, 0.0001),
      mk(4, MarkerType::OuterSurface, 0, 0, 0)};  // same place: 0 < dist fails
  SmoothParams p;
  p.radius_mm = 3.0;
  p.edge_weight = 1.0;
  const SmoothResult r = smooth_markers(in, p);
  EXPECT_LT((r.markers[0].position - Eigen::Vector3d(1.5, 0, 0)).norm(), 1e-12);
}

TEST(SmoothMarkers, IndependentOfMarkerOrder) {
  std::vector<Marker> in;
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-10, 10);
  for (int i = 0; i < 40; ++i)
    in.push_back(mk(i, static_cast<MarkerType>(i % 4), u(rng), u(rng), u(rng)));
  SmoothParams p;
  p.radius_mm = 8;
  p.edge_weight = 3;
  p.iterations = 3;
  const SmoothResult a = smooth_markers(in, p);
  std::vector<Marker> shuffled = in;
  std::shuffle(shuffled.begin(), shuffled.end(), rng);
  const SmoothResult b = smooth_markers(shuffled, p);
  for (const auto& m : b.markers) {
    const auto it = std::find_if(a.markers.begin(), a.markers.end(),
                                 [&](const Marker& x) { return x.id == m.id; });
    EXPECT_LT((it->position - m.position).norm(), 1e-12) << m.id;
  }
}

TEST(SmoothMarkers, EachIterationStartsFromThePreviousPositions) {
  // Three outer surface markers on a line, radius 1.5 mm. Iteration 1: (0.5, 1, 1.5).
  // Iteration 2 from those (not updated in place): (1, 1, 1).
  const std::vector<Marker> in = {mk(1, MarkerType::OuterSurface, 0, 0, 0),
                                  mk(2, MarkerType::OuterSurface, 1, 0, 0),
                                  mk(3, MarkerType::OuterSurface, 2, 0, 0)};
  SmoothParams p;
  p.radius_mm = 1.5;
  p.iterations = 1;
  const SmoothResult one = smooth_markers(in, p);
  EXPECT_NEAR(one.markers[0].position.x(), 0.5, 1e-12);
  EXPECT_NEAR(one.markers[1].position.x(), 1.0, 1e-12);
  EXPECT_NEAR(one.markers[2].position.x(), 1.5, 1e-12);
  p.iterations = 2;
  const SmoothResult two = smooth_markers(in, p);
  for (const auto& m : two.markers) EXPECT_NEAR(m.position.x(), 1.0, 1e-12);
}

TEST(SmoothMarkers, FewerThanThreeMarkersChangeNothing) {
  const std::vector<Marker> in = {mk(1, MarkerType::OuterSurface, 0, 0, 0),
                                  mk(2, MarkerType::OuterSurface, 1, 0, 0)};
  const SmoothResult r = smooth_markers(in, SmoothParams{});
  EXPECT_EQ(r.status, SmoothResult::Status::TooFewMarkers);
  EXPECT_NE(r.message.find("at least 3"), std::string::npos);
  EXPECT_EQ(r.markers[1].position, in[1].position);
}

TEST(SmoothMarkers, ProjectionKeepsSurfaceMarkersOnTheSurface) {
  const SkullMesh head = test::make_symmetric_head(4);
  const SurfaceLocator surface(head);
  std::vector<Marker> in;
  int id = 0;
  for (double a = -0.3; a <= 0.3; a += 0.1)
    for (double b = -0.3; b <= 0.3; b += 0.1)
      in.push_back({id++, MarkerType::OuterSurface,
                    test::head_surface_point(Eigen::Vector3d(a, 1, b).normalized()),
                    MarkerSurface::Mirrored});
  SmoothParams p;
  p.radius_mm = 15;
  const SmoothResult r = smooth_markers(in, p, &surface);
  for (const auto& m : r.markers) EXPECT_LT(surface.closest(m.position).distance, 1e-6);
}

}  // namespace
}  // namespace cranioplan
