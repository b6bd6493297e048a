#include "cranioplan/algorithms/geometry/slices.h"

#include <gtest/gtest.h>

#include <cmath>

#include "support/synthetic.h"

namespace cranioplan {
namespace {

// A volume on an oblique, sheared grid holding a linear function of the patient position:
// trilinear sampling reproduces a linear function exactly, so every slice pixel inside the
// volume must show f at its own position.
TEST(Slices, EverySliceShowsTheVolumeAtItsOwnPatientPosition) {
  Volume v = test::oblique_ball_volume(Eigen::Vector3d(5, -10, 40));
  v.directions.col(2) += 0.15 * v.directions.col(0);
  const auto f = [](const Eigen::Vector3d& p) {
    return 2.0 * p.x() - 3.0 * p.y() + 0.5 * p.z() + 7;
  };
  for (int k = 0; k < v.dims[2]; ++k)
    for (int j = 0; j < v.dims[1]; ++j)
      for (int i = 0; i < v.dims[0]; ++i)
        v.data[v.index(i, j, k)] = static_cast<float>(f(v.world(Eigen::Vector3d(i, j, k))));
  for (SliceOrientation o :
       {SliceOrientation::Axial, SliceOrientation::Coronal, SliceOrientation::Sagittal}) {
    const SliceGeometry s = slice_through(v, o, Eigen::Vector3d(5, -10, 40), 0.7);
    const std::vector<float> img = sample_slice(v, s);
    long long inside = 0, outside = 0;
    for (int r = 0; r < s.height; ++r)
      for (int c = 0; c < s.width; ++c) {
        const float x = img[static_cast<size_t>(r) * s.width + c];
        if (std::isnan(x)) {
          ++outside;
          continue;
        }
        ++inside;
        ASSERT_NEAR(x, f(s.world(c, r)), 2e-3) << to_string(o) << " " << c << "," << r;
      }
    EXPECT_GT(inside, 200) << to_string(o);
    EXPECT_GT(outside, 0) << to_string(o) << ": an oblique volume leaves corners empty";
    EXPECT_NEAR(s.distance(s.world(3, 4)), 0.0, 1e-9);
    EXPECT_LT((s.pixel(s.world(3.5, 7)) - Eigen::Vector2d(3.5, 7)).norm(), 1e-9);
  }
}

// Radiological display: axial from the feet, coronal from the front, sagittal from the left.
TEST(Slices, ScreenDirectionsFollowRadiologicalConvention) {
  const Volume v = test::make_ball_volume(Eigen::Vector3d::Zero(), 5, 20, 1.0, false);
  const SliceGeometry ax = slice_through(v, SliceOrientation::Axial, Eigen::Vector3d::Zero());
  EXPECT_GT(ax.right.x(), 0) << "the patient's left on the screen's right";
  EXPECT_GT(ax.down.y(), 0) << "posterior down, anterior up";
  EXPECT_EQ(
      std::string(ax.edge_labels[0]) + ax.edge_labels[1] + ax.edge_labels[2] + ax.edge_labels[3],
      "RLAP");
  const SliceGeometry co = slice_through(v, SliceOrientation::Coronal, Eigen::Vector3d::Zero());
  EXPECT_GT(co.right.x(), 0);
  EXPECT_LT(co.down.z(), 0) << "superior up";
  EXPECT_EQ(co.normal, Eigen::Vector3d::UnitY());
  const SliceGeometry sa = slice_through(v, SliceOrientation::Sagittal, Eigen::Vector3d::Zero());
  EXPECT_GT(sa.right.y(), 0) << "anterior on the left";
  EXPECT_LT(sa.down.z(), 0);
  EXPECT_EQ(std::string(sa.edge_labels[0]), "A");
  // A point beyond the volume puts the slice on its last plane.
  const SliceGeometry far = slice_through(v, SliceOrientation::Axial, Eigen::Vector3d(0, 0, 500));
  EXPECT_NEAR(far.position_mm, v.world(Eigen::Vector3d(0, 0, 19)).z(), 1e-9);
}

double length(const std::vector<CutSegment>& segments) {
  double l = 0;
  for (const CutSegment& s : segments) l += (s[1] - s[0]).norm();
  return l;
}

TEST(Slices, AMeshIsCutIntoClosedOutlines) {
  const SkullMesh box = build_mesh(test::box_soup({0, 0, 0}, {10, 6, 8}));
  const std::vector<CutSegment> square = cut_mesh(box, Eigen::Vector3d::UnitZ(), 5.0);
  EXPECT_EQ(square.size(), 8u);
  EXPECT_NEAR(length(square), 32.0, 1e-9);
  for (const CutSegment& s : square) EXPECT_NEAR(s[0].z(), 5.0, 1e-12);
  EXPECT_TRUE(cut_mesh(box, Eigen::Vector3d::UnitZ(), 20.0).empty());
  // Through a row of vertices: each segment once.
  EXPECT_NEAR(length(cut_mesh(box, Eigen::Vector3d::UnitZ(), 8.0)), 32.0, 1e-9);

  TriangleSoup s = to_soup(test::make_symmetric_head(4));
  for (auto& p : s.vertices) p = 9.0 * p.normalized();
  const std::vector<CutSegment> circle = cut_mesh(build_mesh(s), Eigen::Vector3d::UnitX(), 3.0);
  const double r = std::sqrt(81.0 - 9.0);
  for (const CutSegment& c : circle)
    for (const Eigen::Vector3d& p : c) {
      EXPECT_NEAR(p.x(), 3.0, 1e-9);
      EXPECT_NEAR(std::hypot(p.y(), p.z()), r, 0.1);
    }
  EXPECT_NEAR(length(circle), 2 * M_PI * r, 0.02 * 2 * M_PI * r);
}

TEST(Slices, WindowAndLevelMapValuesToGrey) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const std::vector<uint8_t> g = window_level({-1000, 0, 40, 80, 3000, nan}, 80, 40);
  EXPECT_EQ(g[0], 0);
  EXPECT_EQ(g[1], 0);
  EXPECT_EQ(g[2], 128);
  EXPECT_EQ(g[3], 255);
  EXPECT_EQ(g[4], 255);
  EXPECT_EQ(g[5], 0) << "outside the volume is black";
}

}  // namespace
}  // namespace cranioplan
