#include "cranioplan/algorithms/quality/thickness_map.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>

#include "cranioplan/algorithms/geometry/distance_transform.h"
#include "cranioplan/algorithms/geometry/surface_locator.h"
#include "cranioplan/algorithms/geometry/voxelize_mesh.h"
#include "cranioplan/model/parallel.h"

namespace cranioplan {

namespace {

// The deepest voxel along the segment from `a` to `b` (sampled every half voxel), in mm.
double deepest_along(const std::vector<float>& depth, const VoxelGrid& grid,
                     const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  const int steps = 1 + static_cast<int>((b - a).norm() / (0.5 * grid.spacing));
  double deepest = 0.0;
  for (int t = 0; t <= steps; ++t) {
    const Eigen::Vector3d v = (a + (b - a) * (double(t) / steps) - grid.origin) / grid.spacing;
    const int i = static_cast<int>(std::lround(v.x())), j = static_cast<int>(std::lround(v.y())),
              k = static_cast<int>(std::lround(v.z()));
    if (i < 0 || j < 0 || k < 0 || i >= grid.dims[0] || j >= grid.dims[1] || k >= grid.dims[2])
      continue;
    deepest = std::max(deepest, static_cast<double>(depth[grid.index(i, j, k)]));
  }
  return deepest;
}

}  // namespace

double thickness_through(const SurfaceLocator& self, const Eigen::Vector3d& at,
                         const Eigen::Vector3d& outward, const std::vector<float>& depth,
                         const VoxelGrid& grid) {
  const auto hit = self.first_hit(at - 1e-4 * outward, at - 200.0 * outward);
  if (!hit) return 0.0;
  const double along = hit->distance + 1e-4;
  const double ball = 2.0 * deepest_along(depth, grid, at, hit->point) + grid.spacing;
  return std::min(along, ball);
}

ThicknessMap thickness_map(const SkullMesh& implant, const SkullMesh* skull,
                           const ThicknessMapParams& params) {
  ThicknessMap map;
  const size_t n = implant.n_vertices();
  map.implant_mm.assign(n, 0.0f);
  if (skull) map.skull_gap_mm.assign(skull->n_vertices(), std::numeric_limits<float>::quiet_NaN());
  if (implant.n_faces() == 0) return map;
  // Area-weighted vertex normals (the face cross products summed).
  std::vector<Eigen::Vector3d> normal(n, Eigen::Vector3d::Zero());
  for (auto fh : implant.faces()) {
    const FaceCorners f = face_corners(implant, fh);
    const Eigen::Vector3d a = f.cross();
    for (int id : f.ids) normal[static_cast<size_t>(id)] += a;
  }
  const auto [lo, hi] = mesh_bounds(implant);
  // Two voxels of margin: the grid's outermost layer counts as outside, and a plate reaching
  // the bounds would read thin at its edges.
  const VoxelGrid grid = VoxelGrid::covering_at_most(lo, hi, std::clamp(params.voxel_mm, 0.05, 2.0),
                                                     std::max(1e5, params.max_voxels), 2);
  const std::vector<float> depth = depth_in_mask(voxelize_mesh(implant, grid), grid);
  const SurfaceLocator self(implant);
  parallel_for(n, [&](size_t begin, size_t end) {
    for (size_t v = begin; v < end; ++v) {
      if (normal[v].norm() == 0) continue;
      const Eigen::Vector3d at =
          to_eigen(implant.point(SkullMesh::VertexHandle(static_cast<int>(v))));
      map.implant_mm[v] =
          static_cast<float>(thickness_through(self, at, normal[v].normalized(), depth, grid));
    }
  });
  std::vector<float> sorted = map.implant_mm;
  std::sort(sorted.begin(), sorted.end());
  map.min_mm = sorted.front();
  map.median_mm = sorted[sorted.size() / 2];
  map.max_mm = sorted.back();
  if (skull) {
    const double reach = std::max(0.0, params.skull_reach_mm);
    const Eigen::Vector3d near_lo = lo - Eigen::Vector3d::Constant(reach),
                          near_hi = hi + Eigen::Vector3d::Constant(reach);
    parallel_for(skull->n_vertices(), [&](size_t begin, size_t end) {
      for (size_t v = begin; v < end; ++v) {
        const Eigen::Vector3d p =
            to_eigen(skull->point(SkullMesh::VertexHandle(static_cast<int>(v))));
        if ((p.array() < near_lo.array()).any() || (p.array() > near_hi.array()).any()) continue;
        const double d = self.closest(p).distance;
        if (d <= reach) map.skull_gap_mm[v] = static_cast<float>(d);
      }
    });
  }
  return map;
}

}  // namespace cranioplan
