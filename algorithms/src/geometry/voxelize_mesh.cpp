#include "cranioplan/algorithms/geometry/voxelize_mesh.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <mutex>

#include "cranioplan/algorithms/geometry/surface_locator.h"
#include "cranioplan/model/parallel.h"

namespace cranioplan {

VoxelGrid VoxelGrid::covering(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi, double spacing,
                              int pad) {
  VoxelGrid g;
  g.spacing = spacing;
  g.origin = lo - Eigen::Vector3d::Constant(pad * spacing);
  for (int a = 0; a < 3; ++a)
    g.dims[a] = static_cast<int>(std::ceil((hi[a] - lo[a]) / spacing)) + 1 + 2 * pad;
  return g;
}

VoxelGrid VoxelGrid::covering_at_most(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi,
                                      double spacing, double max_voxels, int pad) {
  const double budget = std::max(1e3, max_voxels);
  const Eigen::Vector3d extent = (hi - lo).array() + 2.0 * pad * spacing;
  VoxelGrid g = covering(lo, hi, std::max(spacing, std::cbrt(extent.prod() / budget)), pad);
  // The padding and rounding up add a few voxels per axis: coarsen until within the budget.
  while (static_cast<double>(g.size()) > budget) g = covering(lo, hi, g.spacing * 1.01, pad);
  return g;
}

std::pair<Eigen::Vector3d, Eigen::Vector3d> mesh_bounds(const SkullMesh& mesh) {
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector3d hi = -lo;
  for (auto vh : mesh.vertices()) {
    lo = lo.cwiseMin(to_eigen(mesh.point(vh)));
    hi = hi.cwiseMax(to_eigen(mesh.point(vh)));
  }
  return {lo, hi};
}

namespace {

// The faces faces[first, last) (all the mesh's faces when `faces` is null) add their
// crossings to `columns` (crossings(), below).
void add_crossings(const SkullMesh& mesh, const std::vector<int>* faces, const VoxelGrid& grid,
                   int axis, size_t first, size_t last, std::vector<std::vector<float>>& columns) {
  const int u = (axis + 1) % 3, v = (axis + 2) % 3;
  const int nu = grid.dims[u], nv = grid.dims[v];
  // A tiny irrational shift keeps column lines off vertices and edges of regular meshes.
  const double jitter_u = 1.3e-6 * M_PI, jitter_v = 1.7e-6 * M_E;
  for (size_t n = first; n < last; ++n) {
    const auto fh = mesh.face_handle(faces ? (*faces)[n] : static_cast<int>(n));
    Eigen::Vector3d p[3];
    int k = 0;
    for (auto vh : mesh.fv_range(fh)) {
      const Eigen::Vector3d g = (to_eigen(mesh.point(vh)) - grid.origin) / grid.spacing;
      p[k++] = Eigen::Vector3d(g[u], g[v], g[axis]);
    }
    const double x0 = std::min({p[0].x(), p[1].x(), p[2].x()}),
                 x1 = std::max({p[0].x(), p[1].x(), p[2].x()});
    const double y0 = std::min({p[0].y(), p[1].y(), p[2].y()}),
                 y1 = std::max({p[0].y(), p[1].y(), p[2].y()});
    const int i0 = std::max(0, static_cast<int>(std::ceil(x0 - jitter_u)));
    const int i1 = std::min(nu - 1, static_cast<int>(std::floor(x1 - jitter_u)));
    const int j0 = std::max(0, static_cast<int>(std::ceil(y0 - jitter_v)));
    const int j1 = std::min(nv - 1, static_cast<int>(std::floor(y1 - jitter_v)));
    const double det = (p[1].x() - p[0].x()) * (p[2].y() - p[0].y()) -
                       (p[2].x() - p[0].x()) * (p[1].y() - p[0].y());
    if (std::abs(det) < 1e-14) continue;  // parallel to the line: no crossing
    for (int j = j0; j <= j1; ++j)
      for (int i = i0; i <= i1; ++i) {
        const double x = i + jitter_u, y = j + jitter_v;
        // Barycentric coordinates of (x, y) in the projected triangle.
        const double b1 =
            ((x - p[0].x()) * (p[2].y() - p[0].y()) - (p[2].x() - p[0].x()) * (y - p[0].y())) / det;
        const double b2 =
            ((p[1].x() - p[0].x()) * (y - p[0].y()) - (x - p[0].x()) * (p[1].y() - p[0].y())) / det;
        if (b1 < 0 || b2 < 0 || b1 + b2 > 1) continue;
        const double z = p[0].z() + b1 * (p[1].z() - p[0].z()) + b2 * (p[2].z() - p[0].z());
        columns[static_cast<size_t>(j) * nu + i].push_back(static_cast<float>(z));
      }
  }
}

// The heights (in voxel units along axis w) at which a line along w through each voxel column
// (u, v) crosses the mesh, w = `axis` and (u, v) the other two in cyclic order; in no
// particular order (the callers sort them). The faces are read on all threads, each into
// columns of its own, appended in thread order. `locator` (the mesh's): only the faces it
// finds over the lines are read (a face elsewhere crosses none of them).
std::vector<std::vector<float>> crossings(const SkullMesh& mesh, const VoxelGrid& grid, int axis,
                                          const SurfaceLocator* locator) {
  const size_t columns = static_cast<size_t>(grid.dims[(axis + 1) % 3]) * grid.dims[(axis + 2) % 3];
  std::vector<int> near;
  if (locator) {
    // The lines' slab, a voxel wider across them, unbounded along them.
    Eigen::Vector3d lo = grid.origin - Eigen::Vector3d::Constant(grid.spacing),
                    hi = grid.center(grid.dims[0] - 1, grid.dims[1] - 1, grid.dims[2] - 1) +
                         Eigen::Vector3d::Constant(grid.spacing);
    lo[axis] = -std::numeric_limits<double>::infinity();
    hi[axis] = std::numeric_limits<double>::infinity();
    locator->faces_near(lo, hi, 0.0, near);
  }
  const std::vector<int>* faces = locator ? &near : nullptr;
  std::mutex m;
  std::map<size_t, std::vector<std::vector<float>>> parts;  // by the range's first face
  parallel_for(
      faces ? faces->size() : mesh.n_faces(),
      [&](size_t first, size_t last) {
        std::vector<std::vector<float>> part(columns);
        add_crossings(mesh, faces, grid, axis, first, last, part);
        const std::lock_guard<std::mutex> lock(m);
        parts.emplace(first, std::move(part));
      },
      50000);
  if (parts.empty()) return std::vector<std::vector<float>>(columns);
  std::vector<std::vector<float>> all = std::move(parts.begin()->second);
  for (auto p = std::next(parts.begin()); p != parts.end(); ++p)
    for (size_t c = 0; c < columns; ++c)
      all[c].insert(all[c].end(), p->second[c].begin(), p->second[c].end());
  return all;
}

std::vector<uint8_t> voxelize(const SkullMesh& mesh, const VoxelGrid& grid,
                              const VoxelizeParams& params, const SurfaceLocator* locator) {
  std::vector<uint8_t> mask(grid.size(), 0);
  const int nx = grid.dims[0], ny = grid.dims[1], nz = grid.dims[2];
  std::vector<std::vector<float>> columns = crossings(mesh, grid, 2, locator);
  // Lines along x and y, made only when a line along z passes through a hole.
  std::vector<std::vector<float>> along_x, along_y;
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      auto& c = columns[static_cast<size_t>(j) * nx + i];
      std::sort(c.begin(), c.end());
      if (c.size() % 2 != 0 && params.vote_through_holes) {
        if (along_x.empty()) {
          along_x = crossings(mesh, grid, 0, locator);
          along_y = crossings(mesh, grid, 1, locator);
          for (auto* lines : {&along_x, &along_y})
            for (auto& line : *lines) std::sort(line.begin(), line.end());
        }
        for (int k = 0; k < nz; ++k) {
          // Each line along x or y through the voxel votes when it crosses the surface an even
          // number of times: inside when an odd number of crossings lies before the voxel.
          int vote = 0;
          const auto cast = [&](const std::vector<float>& line, int at) {
            if (line.size() % 2 != 0) return;
            const size_t before = static_cast<size_t>(
                std::upper_bound(line.begin(), line.end(), static_cast<float>(at)) - line.begin());
            vote += before % 2 == 1 ? 1 : -1;
          };
          cast(along_x[static_cast<size_t>(k) * ny + j], i);  // x: columns over (y, z)
          cast(along_y[static_cast<size_t>(i) * nz + k], j);  // y: columns over (z, x)
          if (vote != 0) {
            mask[grid.index(i, j, k)] = vote > 0;
            continue;
          }
          // No line votes: parity from below along z, as for a closed surface.
          const size_t below = static_cast<size_t>(
              std::upper_bound(c.begin(), c.end(), static_cast<float>(k)) - c.begin());
          mask[grid.index(i, j, k)] = below % 2 == 1 && below < c.size();
        }
        continue;
      }
      if (c.size() < 2) continue;
      for (size_t s = 0; s + 1 < c.size(); s += 2) {
        const int k0 = std::max(0, static_cast<int>(std::ceil(c[s])));
        const int k1 = std::min(nz - 1, static_cast<int>(std::floor(c[s + 1])));
        for (int kk = k0; kk <= k1; ++kk) mask[grid.index(i, j, kk)] = 1;
      }
    }
  return mask;
}

}  // namespace

std::vector<uint8_t> voxelize_mesh(const SkullMesh& mesh, const VoxelGrid& grid,
                                   const VoxelizeParams& params) {
  return voxelize(mesh, grid, params, nullptr);
}

std::vector<uint8_t> voxelize_mesh(const SkullMesh& mesh, const VoxelGrid& grid,
                                   const VoxelizeParams& params, const SurfaceLocator& locator) {
  return voxelize(mesh, grid, params, &locator);
}

Volume mask_volume(const std::vector<uint8_t>& mask, const VoxelGrid& grid) {
  Volume v;
  v.dims = grid.dims;
  v.directions = Eigen::Matrix3d::Identity() * grid.spacing;
  v.origin = grid.origin;
  v.kind = VolumeKind::Mask;
  v.data.assign(mask.begin(), mask.end());
  return v;
}

}  // namespace cranioplan
