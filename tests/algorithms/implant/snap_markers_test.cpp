#include "cranioplan/algorithms/implant/snap_markers.h"

#include <gtest/gtest.h>

#include "cranioplan/algorithms/geometry/surface_locator.h"
#include "support/synthetic.h"

namespace cranioplan {
namespace {

// Two boxes standing for the skull (top face at z = 10) and its mirror (top face at z = 20).
const SkullMesh& original() {
  static const SkullMesh m = build_mesh(test::box_soup({0, 0, 0}, {10, 10, 10}));
  return m;
}
const SkullMesh& mirrored() {
  static const SkullMesh m = build_mesh(test::box_soup({0, 0, 10}, {10, 10, 20}));
  return m;
}

TEST(SnapMarkers, EachMarkerGoesToTheClosestPointOfItsOwnSurface) {
  const SurfaceLocator a(original()), b(mirrored());
  const std::vector<Marker> markers = {
      {1, MarkerType::OuterEdge, {5, 5, 11.5}, MarkerSurface::Original},
      {2, MarkerType::OuterSurface, {5, 5, 22}, MarkerSurface::Mirrored}};
  const SnapMarkersResult r = snap_markers(markers, a, &b);
  ASSERT_EQ(r.status, SnapMarkersResult::Status::Snapped) << r.message;
  EXPECT_LT((r.markers[0].position - Eigen::Vector3d(5, 5, 10)).norm(), 1e-9);
  EXPECT_LT((r.markers[1].position - Eigen::Vector3d(5, 5, 20)).norm(), 1e-9);
  EXPECT_NEAR(r.max_distance_mm, 2.0, 1e-9);
  EXPECT_EQ(r.markers[1].id, 2);
  EXPECT_EQ(r.message, "snapped 2 markers");
  // Without a mirror every marker goes to the original.
  const SnapMarkersResult alone = snap_markers({markers[1]}, a, nullptr, {15.0});
  EXPECT_LT((alone.markers[0].position - Eigen::Vector3d(5, 5, 10)).norm(), 1e-9);
}

TEST(SnapMarkers, AMarkerTooFarIsRefusedAndNothingMoves) {
  const SurfaceLocator a(original());
  const std::vector<Marker> markers = {
      {1, MarkerType::OuterEdge, {5, 5, 11}, MarkerSurface::Original},
      {8, MarkerType::InnerEdge, {5, 5, 40}, MarkerSurface::Original}};
  const SnapMarkersResult r = snap_markers(markers, a, nullptr, {10.0});
  EXPECT_EQ(r.status, SnapMarkersResult::Status::TooFar);
  EXPECT_EQ(r.message, "marker 8 (inner edge) is 30.0 mm from the original skull (limit 10.0 mm)");
  EXPECT_EQ(r.markers[0].position, markers[0].position) << "the input, unchanged";
}

}  // namespace
}  // namespace cranioplan
