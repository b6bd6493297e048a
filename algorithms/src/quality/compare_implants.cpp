#include "cranioplan/algorithms/quality/compare_implants.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>

#include "cranioplan/algorithms/geometry/point_index.h"
#include "cranioplan/algorithms/geometry/surface_locator.h"
#include "cranioplan/algorithms/geometry/voxelize_mesh.h"

namespace cranioplan {
namespace {

std::vector<Eigen::Vector3d> surface_voxels(const std::vector<uint8_t>& m, const VoxelGrid& g) {
  std::vector<Eigen::Vector3d> out;
  auto at = [&](int i, int j, int k) {
    if (i < 0 || j < 0 || k < 0 || i >= g.dims[0] || j >= g.dims[1] || k >= g.dims[2]) return false;
    return m[g.index(i, j, k)] != 0;
  };
  for (int k = 0; k < g.dims[2]; ++k)
    for (int j = 0; j < g.dims[1]; ++j)
      for (int i = 0; i < g.dims[0]; ++i)
        if (at(i, j, k) && !(at(i - 1, j, k) && at(i + 1, j, k) && at(i, j - 1, k) &&
                             at(i, j + 1, k) && at(i, j, k - 1) && at(i, j, k + 1)))
          out.push_back(g.center(i, j, k));
  return out;
}

std::vector<double> distances(const std::vector<Eigen::Vector3d>& from, const PointIndex& to) {
  std::vector<double> d;
  d.reserve(from.size());
  for (const auto& p : from) {
    double d2;
    to.nearest(p, &d2);
    d.push_back(std::sqrt(d2));
  }
  return d;
}

double dice(long long a, long long b, long long both) {
  return a + b > 0 ? 2.0 * static_cast<double>(both) / static_cast<double>(a + b) : 1.0;
}

}  // namespace

CompareResult compare_implants(const SkullMesh& a, const SkullMesh& b,
                               const SkullMesh* defective_skull, const CompareParams& params) {
  const auto t0 = std::chrono::steady_clock::now();
  CompareResult r;
  auto [lo_a, hi_a] = mesh_bounds(a);
  auto [lo_b, hi_b] = mesh_bounds(b);
  const VoxelGrid grid = VoxelGrid::covering(lo_a.cwiseMin(lo_b), hi_a.cwiseMax(hi_b),
                                             std::clamp(params.spacing_mm, 0.1, 2.0));
  const std::vector<uint8_t> ma = voxelize_mesh(a, grid), mb = voxelize_mesh(b, grid);
  std::unique_ptr<SurfaceLocator> skull;
  std::unique_ptr<PointIndex> skull_vertices;
  double longest_edge = 0.0;
  if (defective_skull && defective_skull->n_faces() > 0) {
    skull = std::make_unique<SurfaceLocator>(*defective_skull);
    std::vector<Eigen::Vector3d> pts;
    for (auto vh : defective_skull->vertices()) pts.push_back(to_eigen(defective_skull->point(vh)));
    skull_vertices = std::make_unique<PointIndex>(std::move(pts));
    for (auto eh : defective_skull->edges())
      longest_edge = std::max(longest_edge, defective_skull->calc_edge_length(eh));
  }
  // Within `boundary_mm` of the skull? The nearest vertex bounds the distance from below by
  // (its distance − longest edge), which settles most voxels without the exact query.
  auto near_skull = [&](const Eigen::Vector3d& p) {
    double d2;
    skull_vertices->nearest(p, &d2);
    const double dv = std::sqrt(d2);
    if (dv <= params.boundary_mm) return true;
    if (dv - longest_edge > params.boundary_mm) return false;
    return skull->closest(p).distance <= params.boundary_mm;
  };
  long long near_a = 0, near_b = 0, near_both = 0;
  for (int k = 0; k < grid.dims[2]; ++k)
    for (int j = 0; j < grid.dims[1]; ++j)
      for (int i = 0; i < grid.dims[0]; ++i) {
        const size_t idx = grid.index(i, j, k);
        if (!ma[idx] && !mb[idx]) continue;
        r.voxels_a += ma[idx];
        r.voxels_b += mb[idx];
        r.voxels_both += ma[idx] && mb[idx];
        if (skull && near_skull(grid.center(i, j, k))) {
          near_a += ma[idx];
          near_b += mb[idx];
          near_both += ma[idx] && mb[idx];
        }
      }
  r.dice = dice(r.voxels_a, r.voxels_b, r.voxels_both);
  if (skull) r.boundary_dice = dice(near_a, near_b, near_both);
  r.volume_a_mm3 = static_cast<double>(r.voxels_a) * grid.voxel_volume();
  r.volume_b_mm3 = static_cast<double>(r.voxels_b) * grid.voxel_volume();

  const auto sa = surface_voxels(ma, grid), sb = surface_voxels(mb, grid);
  if (sa.empty() || sb.empty()) {
    r.hausdorff_mm = r.hd95_mm = r.mean_surface_mm =
        sa.empty() && sb.empty() ? 0.0 : std::numeric_limits<double>::infinity();
  } else {
    std::vector<double> d = distances(sa, PointIndex(sb));
    const std::vector<double> d_ba = distances(sb, PointIndex(sa));
    d.insert(d.end(), d_ba.begin(), d_ba.end());
    double sum = 0.0;
    for (double x : d) sum += x;
    r.mean_surface_mm = sum / static_cast<double>(d.size());
    std::sort(d.begin(), d.end());
    r.hausdorff_mm = d.back();
    r.hd95_mm = d[std::min(
        d.size() - 1, static_cast<size_t>(std::ceil(0.95 * static_cast<double>(d.size()))) - 1)];
  }
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return r;
}

}  // namespace cranioplan
