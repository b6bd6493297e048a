#include "cranioplan/algorithms/geometry/slices.h"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <limits>

namespace cranioplan {

const char* to_string(SliceOrientation o) {
  switch (o) {
    case SliceOrientation::Axial:
      return "axial";
    case SliceOrientation::Coronal:
      return "coronal";
    case SliceOrientation::Sagittal:
      return "sagittal";
  }
  return "axial";
}

Eigen::Vector2d SliceGeometry::pixel(const Eigen::Vector3d& point) const {
  const Eigen::Vector3d d = point - origin;
  return {d.dot(right) / right.squaredNorm(), d.dot(down) / down.squaredNorm()};
}

SliceGeometry slice_through(const Volume& volume, SliceOrientation orientation,
                            const Eigen::Vector3d& point, double pixel_mm) {
  // The volume's extent in the patient frame: its eight corners.
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector3d hi = -lo;
  for (int c = 0; c < 8; ++c) {
    const Eigen::Vector3d ijk((c & 1) ? volume.dims[0] - 1 : 0, (c & 2) ? volume.dims[1] - 1 : 0,
                              (c & 4) ? volume.dims[2] - 1 : 0);
    const Eigen::Vector3d w = volume.world(ijk);
    lo = lo.cwiseMin(w);
    hi = hi.cwiseMax(w);
  }
  const double px = pixel_mm > 0 ? pixel_mm : std::max(0.1, volume.spacing().minCoeff());
  SliceGeometry s;
  s.orientation = orientation;
  // Screen right and down as patient axes (sign), and the axis across.
  int ax_right = 0, ax_down = 1, ax_normal = 2;
  double sign_right = 1, sign_down = 1;
  switch (orientation) {
    case SliceOrientation::Axial:  // right: +x (patient's left), down: +y (posterior)
      s.edge_labels = {"R", "L", "A", "P"};
      break;
    case SliceOrientation::Coronal:  // right: +x, down: -z (inferior)
      ax_down = 2, ax_normal = 1, sign_down = -1;
      s.edge_labels = {"R", "L", "S", "I"};
      break;
    case SliceOrientation::Sagittal:  // right: +y (posterior), down: -z
      ax_right = 1, ax_down = 2, ax_normal = 0, sign_down = -1;
      s.edge_labels = {"A", "P", "S", "I"};
      break;
  }
  s.right = sign_right * px * Eigen::Vector3d::Unit(ax_right);
  s.down = sign_down * px * Eigen::Vector3d::Unit(ax_down);
  s.normal = Eigen::Vector3d::Unit(ax_normal);
  s.width = static_cast<int>(std::floor((hi[ax_right] - lo[ax_right]) / px)) + 1;
  s.height = static_cast<int>(std::floor((hi[ax_down] - lo[ax_down]) / px)) + 1;
  s.position_mm = std::clamp(point[ax_normal], lo[ax_normal], hi[ax_normal]);
  s.origin = Eigen::Vector3d::Zero();
  s.origin[ax_right] = sign_right > 0 ? lo[ax_right] : hi[ax_right];
  s.origin[ax_down] = sign_down > 0 ? lo[ax_down] : hi[ax_down];
  s.origin[ax_normal] = s.position_mm;
  return s;
}

std::vector<float> sample_slice(const Volume& volume, const SliceGeometry& slice) {
  std::vector<float> out(static_cast<size_t>(slice.width) * slice.height,
                         std::numeric_limits<float>::quiet_NaN());
  const Eigen::Matrix3d to_index = volume.directions.inverse();
  const Eigen::Vector3d step_c = to_index * slice.right, step_r = to_index * slice.down;
  const Eigen::Vector3d start = to_index * (slice.origin - volume.origin);
  for (int r = 0; r < slice.height; ++r)
    for (int c = 0; c < slice.width; ++c) {
      const Eigen::Vector3d q = start + c * step_c + r * step_r;
      const Eigen::Vector3d f = q.array().floor();
      const int i = static_cast<int>(f.x()), j = static_cast<int>(f.y()),
                k = static_cast<int>(f.z());
      // Samples on the volume's last index along an axis interpolate within it.
      auto clamp_hi = [](int i0, int n) { return std::min(i0, n - 2); };
      if (q.x() < 0 || q.y() < 0 || q.z() < 0 || q.x() > volume.dims[0] - 1 ||
          q.y() > volume.dims[1] - 1 || q.z() > volume.dims[2] - 1)
        continue;
      const int i0 = volume.dims[0] > 1 ? clamp_hi(i, volume.dims[0]) : 0;
      const int j0 = volume.dims[1] > 1 ? clamp_hi(j, volume.dims[1]) : 0;
      const int k0 = volume.dims[2] > 1 ? clamp_hi(k, volume.dims[2]) : 0;
      const int i1 = std::min(i0 + 1, volume.dims[0] - 1),
                j1 = std::min(j0 + 1, volume.dims[1] - 1),
                k1 = std::min(k0 + 1, volume.dims[2] - 1);
      const double tx = q.x() - i0, ty = q.y() - j0, tz = q.z() - k0;
      auto at = [&](int a, int b, int cc) { return static_cast<double>(volume.at(a, b, cc)); };
      const double c00 = at(i0, j0, k0) * (1 - tx) + at(i1, j0, k0) * tx;
      const double c10 = at(i0, j1, k0) * (1 - tx) + at(i1, j1, k0) * tx;
      const double c01 = at(i0, j0, k1) * (1 - tx) + at(i1, j0, k1) * tx;
      const double c11 = at(i0, j1, k1) * (1 - tx) + at(i1, j1, k1) * tx;
      const double v = (c00 * (1 - ty) + c10 * ty) * (1 - tz) + (c01 * (1 - ty) + c11 * ty) * tz;
      out[static_cast<size_t>(r) * slice.width + c] = static_cast<float>(v);
    }
  return out;
}

std::vector<CutSegment> cut_mesh(const SkullMesh& mesh, const Eigen::Vector3d& normal, double d) {
  std::vector<CutSegment> out;
  for (auto fh : mesh.faces()) {
    std::array<Eigen::Vector3d, 3> p;
    std::array<double, 3> s;
    int k = 0;
    for (auto vh : mesh.fv_range(fh)) {
      p[k] = to_eigen(mesh.point(vh));
      s[k] = normal.dot(p[k]) - d;
      ++k;
    }
    // A vertex exactly on the plane counts as above it, so that a cut through a vertex gives
    // each of its triangles' segments once and the polygons stay closed.
    std::array<bool, 3> above{s[0] >= 0, s[1] >= 0, s[2] >= 0};
    if (above[0] == above[1] && above[1] == above[2]) continue;
    Eigen::Vector3d ends[2];
    int n = 0;
    for (int e = 0; e < 3; ++e) {
      const int a = e, b = (e + 1) % 3;
      if (above[a] == above[b]) continue;
      const double t = s[a] / (s[a] - s[b]);
      ends[n++] = p[a] + t * (p[b] - p[a]);
    }
    if (n == 2) out.push_back({ends[0], ends[1]});
  }
  return out;
}

std::vector<uint8_t> window_level(const std::vector<float>& values, double window, double level) {
  std::vector<uint8_t> out(values.size(), 0);
  const double w = std::max(window, 1e-6), lo = level - 0.5 * w;
  for (size_t i = 0; i < values.size(); ++i) {
    const float v = values[i];
    if (std::isnan(v)) continue;
    out[i] = static_cast<uint8_t>(std::clamp(std::lround(255.0 * (v - lo) / w), 0L, 255L));
  }
  return out;
}

}  // namespace cranioplan
