#include "cranioplan/algorithms/geometry/mesh_components.h"

#include <gtest/gtest.h>

#include <cmath>

#include "support/synthetic.h"

namespace cranioplan {
namespace {

// Three boxes: a large one, a small one 5 mm beside it, and a middle one touching the large
// one at a corner (one shared vertex joins them into one piece).
TriangleSoup three_boxes() {
  TriangleSoup s;
  auto add = [&s](const TriangleSoup& b) {
    const int n = static_cast<int>(s.vertices.size());
    s.vertices.insert(s.vertices.end(), b.vertices.begin(), b.vertices.end());
    for (const Eigen::Vector3i& t : b.triangles)
      s.triangles.push_back(t + Eigen::Vector3i::Constant(n));
  };
  add(test::box_soup({0, 0, 0}, {10, 10, 10}));
  add(test::box_soup({15, 0, 0}, {17, 2, 2}));
  add(test::box_soup({-4, -4, -4}, {0, 0, 0}));
  // Weld the middle box's corner (0,0,0) to the large box's.
  const int corner_large = 0;
  for (int v = 0; v < static_cast<int>(s.vertices.size()); ++v)
    if (v >= 16 && s.vertices[v].isZero())
      for (Eigen::Vector3i& t : s.triangles)
        for (int k = 0; k < 3; ++k)
          if (t[k] == v) t[k] = corner_large;
  return s;
}

TEST(MeshComponents, PiecesAreLabelledLargestFirst) {
  const TriangleSoup s = three_boxes();
  ASSERT_TRUE(s.vertices[0].isZero());
  const SoupComponents c = soup_components(s);
  ASSERT_EQ(c.sizes.size(), 2u) << "the corner joins two boxes";
  EXPECT_EQ(c.sizes[0], 24);
  EXPECT_EQ(c.sizes[1], 12);
  EXPECT_EQ(c.label[0], 0);
  EXPECT_EQ(c.label[12], 1);  // the small box's first triangle
  const TriangleSoup largest = keep_largest_pieces(s, c, 1);
  EXPECT_EQ(largest.triangles.size(), 24u);
  for (const Eigen::Vector3i& t : largest.triangles)
    EXPECT_LT(t.maxCoeff(), static_cast<int>(largest.vertices.size()));
  EXPECT_EQ(largest.vertices.size(), 15u) << "8 + 8 corners, one shared; unused ones dropped";
  const TriangleSoup small = keep_pieces(s, c, {false, true});
  EXPECT_EQ(small.triangles.size(), 12u);
  EXPECT_EQ(small.vertices.size(), 8u);
}

TEST(MeshComponents, BoxesMeasureTheGapBetweenPieces) {
  const TriangleSoup s = three_boxes();
  const SoupComponents c = soup_components(s);
  const std::vector<PieceBox> boxes = piece_boxes(s, c);
  ASSERT_EQ(boxes.size(), 2u);
  EXPECT_EQ(boxes[0].lo, Eigen::Vector3d(-4, -4, -4));
  EXPECT_EQ(boxes[0].hi, Eigen::Vector3d(10, 10, 10));
  EXPECT_DOUBLE_EQ(boxes[0].gap_to(boxes[1]), 5.0);
  EXPECT_DOUBLE_EQ(boxes[1].gap_to(boxes[0]), 5.0);
  EXPECT_DOUBLE_EQ(boxes[0].gap_to(boxes[0]), 0.0);
  PieceBox corner;
  corner.lo = Eigen::Vector3d(13, 13, 13);
  corner.hi = Eigen::Vector3d(20, 20, 20);
  EXPECT_NEAR(boxes[0].gap_to(corner), std::sqrt(27.0), 1e-12);
}

}  // namespace
}  // namespace cranioplan
