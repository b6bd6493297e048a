// Solid voxelisation of skull surfaces that exporters leave open: a surface cut where the scan
// ends (no cap over the cut), tilted or not, must give the same solid above the cut as the
// closed surface does; and a closed surface gives the same mask with or without the votes.
#include "cranioplan/algorithms/geometry/voxelize_mesh.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include "cranioplan/algorithms/geometry/surface_locator.h"
#include "cranioplan/model/parallel.h"
#include "support/synthetic.h"

namespace cranioplan {
namespace {

// A skull-like shell bounded by two smooth closed surfaces: the synthetic head outside, the
// same head scaled by 0.93 about its centre inside, wound inward.
SkullMesh hollow_head(int subdivisions = 5) {
  const SkullMesh outer = test::make_symmetric_head(subdivisions);
  const auto [lo, hi] = mesh_bounds(outer);
  const Eigen::Vector3d c = (lo + hi) / 2;
  TriangleSoup soup;
  const int n = static_cast<int>(outer.n_vertices());
  for (auto vh : outer.vertices()) soup.vertices.push_back(to_eigen(outer.point(vh)));
  for (auto vh : outer.vertices())
    soup.vertices.push_back(c + 0.93 * (to_eigen(outer.point(vh)) - c));
  for (auto fh : outer.faces()) {
    Eigen::Vector3i t;
    int k = 0;
    for (auto vh : outer.fv_range(fh)) t[k++] = vh.idx();
    soup.triangles.push_back(t);
    soup.triangles.push_back(Eigen::Vector3i(t[0], t[2], t[1]) + Eigen::Vector3i::Constant(n));
  }
  return build_mesh(soup);
}

// Within a triangle's size of the cut the open surface's ragged edge differs from the plane.
constexpr double kEdge = 3.0;

struct Agreement {
  long long compared = 0, differing = 0;
  double highest = 0;
};

// Voxels more than `margin` mm above the cut plane where the two masks differ, and the highest
// of them above the plane.
Agreement compare_above(const std::vector<uint8_t>& a, const std::vector<uint8_t>& b,
                        const VoxelGrid& g, const Eigen::Vector3d& point, const Eigen::Vector3d& up,
                        double margin) {
  Agreement r;
  for (int k = 0; k < g.dims[2]; ++k)
    for (int j = 0; j < g.dims[1]; ++j)
      for (int i = 0; i < g.dims[0]; ++i) {
        if ((g.center(i, j, k) - point).dot(up) <= margin) continue;
        ++r.compared;
        r.differing += a[g.index(i, j, k)] != b[g.index(i, j, k)];
        if (a[g.index(i, j, k)] != b[g.index(i, j, k)])
          r.highest = std::max(r.highest, (g.center(i, j, k) - point).dot(up));
      }
  return r;
}

TEST(VoxelizeMesh, ASkullOpenWhereTheScanEndsIsSolidAboveTheCut) {
  const SkullMesh closed = hollow_head();
  const auto [lo, hi] = mesh_bounds(closed);
  const VoxelGrid g = VoxelGrid::covering(lo, hi, 1.0);
  const std::vector<uint8_t> truth = voxelize_mesh(closed, g);
  long long bone = 0;
  for (uint8_t v : truth) bone += v;
  ASSERT_GT(bone, 10000);

  const Eigen::Vector3d centre = (lo + hi) / 2;
  // A cut across the skull's lower third: level (an axial scan), tilted 20° (a gantry tilt or
  // an oblique acquisition), and from the side.
  const Eigen::Vector3d level = Eigen::Vector3d::UnitZ();
  const Eigen::Vector3d tilted =
      Eigen::AngleAxisd(20.0 * M_PI / 180.0, Eigen::Vector3d::UnitX()) * level;
  struct Case {
    const char* name;
    Eigen::Vector3d up;
    Eigen::Vector3d point;
  };
  for (const Case& c : {Case{"level", level, centre - 0.2 * (hi.z() - lo.z()) * level},
                        Case{"tilted", tilted, centre - 0.2 * (hi.z() - lo.z()) * level},
                        Case{"side", Eigen::Vector3d::UnitX(),
                             centre - 0.3 * (hi.x() - lo.x()) * Eigen::Vector3d::UnitX()}}) {
    SCOPED_TRACE(c.name);
    const SkullMesh open = test::cut_open(closed, c.point, c.up);
    ASSERT_LT(open.n_faces(), closed.n_faces());
    const Agreement voted = compare_above(voxelize_mesh(open, g), truth, g, c.point, c.up, kEdge);
    EXPECT_EQ(voted.differing, 0) << "of " << voted.compared << ", up to " << voted.highest;
    // Parity along z alone is wrong wherever a vertical line passes through the cut.
    VoxelizeParams z_only;
    z_only.vote_through_holes = false;
    const Agreement parity =
        compare_above(voxelize_mesh(open, g, z_only), truth, g, c.point, c.up, kEdge);
    if (std::string(c.name) != "side") {
      EXPECT_GT(parity.differing, voted.compared / 100);
    }
  }
}

TEST(VoxelizeMesh, AClosedSurfaceGivesTheSameMaskWithOrWithoutVotes) {
  const SkullMesh closed = hollow_head();
  const auto [lo, hi] = mesh_bounds(closed);
  const VoxelGrid g = VoxelGrid::covering(lo, hi, 0.7);
  VoxelizeParams z_only;
  z_only.vote_through_holes = false;
  EXPECT_EQ(voxelize_mesh(closed, g), voxelize_mesh(closed, g, z_only));
}

// The crossings are gathered on all threads (a mesh of 160,000 faces is read in two halves):
// the masks, closed and open at a cut (votes along three axes), are those of one thread.
TEST(VoxelizeMesh, TheMaskIsTheSameOnOneThreadAndOnTwo) {
  const SkullMesh closed = hollow_head(6);
  ASSERT_GT(closed.n_faces(), 100000u);
  const auto [lo, hi] = mesh_bounds(closed);
  const SkullMesh open =
      test::cut_open(closed, (lo + hi) / 2 - 0.2 * (hi.z() - lo.z()) * Eigen::Vector3d::UnitZ(),
                     Eigen::Vector3d::UnitZ());
  const VoxelGrid g = VoxelGrid::covering(lo, hi, 0.8);
  for (const SkullMesh* mesh : {&closed, &open}) {
    std::vector<uint8_t> masks[2];
    for (int threads : {1, 2}) {
      set_thread_count(threads);
      masks[threads - 1] = voxelize_mesh(*mesh, g);
    }
    set_thread_count(0);
    long long inside = 0;
    for (uint8_t v : masks[0]) inside += v;
    EXPECT_GT(inside, 10000);
    EXPECT_EQ(masks[0], masks[1]);
  }
}

// Read through the mesh's locator (only the faces over the grid's lines), the mask is the one
// all the faces give: closed and cut open (the lines through the cut vote along x and y), on
// a grid over a small part of the surface, over its cut, and over the whole.
TEST(VoxelizeMesh, ThroughTheMeshsLocatorTheMaskIsTheSame) {
  const SkullMesh closed = hollow_head(6);
  const auto [lo, hi] = mesh_bounds(closed);
  const Eigen::Vector3d mid = (lo + hi) / 2, size = hi - lo;
  const SkullMesh open = test::cut_open(closed, mid - 0.2 * size.z() * Eigen::Vector3d::UnitZ(),
                                        Eigen::Vector3d::UnitZ());
  const VoxelGrid grids[] = {
      VoxelGrid::covering(mid + Eigen::Vector3d(0.3 * size.x(), -10, -10),
                          mid + Eigen::Vector3d(0.5 * size.x() + 5, 10, 10), 0.25),
      VoxelGrid::covering(mid + Eigen::Vector3d(0.3 * size.x(), -15, -0.2 * size.z() - 10),
                          mid + Eigen::Vector3d(0.5 * size.x() + 5, 15, -0.2 * size.z() + 10), 0.3),
      VoxelGrid::covering(lo, hi, 0.8)};
  for (const SkullMesh* mesh : {&closed, &open}) {
    const SurfaceLocator locator(*mesh);
    for (const VoxelGrid& g : grids) {
      const std::vector<uint8_t> all = voxelize_mesh(*mesh, g),
                                 near = voxelize_mesh(*mesh, g, VoxelizeParams{}, locator);
      long long inside = 0;
      for (uint8_t v : all) inside += v;
      EXPECT_GT(inside, 1000);
      EXPECT_EQ(near, all);
    }
  }
}

}  // namespace
}  // namespace cranioplan
