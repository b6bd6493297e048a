#include "cranioplan/model/marker.h"

#include <gtest/gtest.h>

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

TEST(Markers, EdgeMarkersBelongToTheOriginalAndSurfaceMarkersToTheMirror) {
  EXPECT_TRUE(is_edge(MarkerType::OuterEdge));
  EXPECT_TRUE(is_edge(MarkerType::InnerEdge));
  EXPECT_FALSE(is_edge(MarkerType::OuterSurface));
  EXPECT_EQ(default_surface(MarkerType::InnerEdge), MarkerSurface::Original);
  EXPECT_EQ(default_surface(MarkerType::InnerSurface), MarkerSurface::Mirrored);
  EXPECT_STREQ(to_string(MarkerType::OuterEdge), "outer edge");
  EXPECT_STREQ(to_string(MarkerType::InnerSurface), "inner surface");
}

}  // namespace
}  // namespace cranioplan
