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

namespace {

// The volume at index-space position q (trilinear); NaN outside the samples.
double at_index(const Volume& volume, const Eigen::Vector3d& q) {
  for (int a = 0; a < 3; ++a)
    if (!(q[a] >= 0.0) || q[a] > volume.dims[a] - 1)
      return std::numeric_limits<double>::quiet_NaN();
  // Samples on the last index along an axis interpolate within the last cell.
  std::array<int, 3> i0{}, i1{};
  Eigen::Vector3d t;
  for (int a = 0; a < 3; ++a) {
    i0[a] = volume.dims[a] > 1 ? std::min(static_cast<int>(q[a]), volume.dims[a] - 2) : 0;
    i1[a] = std::min(i0[a] + 1, volume.dims[a] - 1);
    t[a] = q[a] - i0[a];
  }
  auto at = [&](int x, int y, int z) { return static_cast<double>(volume.at(x, y, z)); };
  const double c00 = at(i0[0], i0[1], i0[2]) * (1 - t.x()) + at(i1[0], i0[1], i0[2]) * t.x();
  const double c10 = at(i0[0], i1[1], i0[2]) * (1 - t.x()) + at(i1[0], i1[1], i0[2]) * t.x();
  const double c01 = at(i0[0], i0[1], i1[2]) * (1 - t.x()) + at(i1[0], i0[1], i1[2]) * t.x();
  const double c11 = at(i0[0], i1[1], i1[2]) * (1 - t.x()) + at(i1[0], i1[1], i1[2]) * t.x();
  return (c00 * (1 - t.y()) + c10 * t.y()) * (1 - t.z()) +
         (c01 * (1 - t.y()) + c11 * t.y()) * t.z();
}

}  // namespace

double sample_volume(const Volume& volume, const Eigen::Vector3d& point) {
  return at_index(volume, volume.directions.inverse() * (point - volume.origin));
}

std::vector<float> sample_slice(const Volume& volume, const SliceGeometry& slice) {
  std::vector<float> out(static_cast<size_t>(slice.width) * slice.height);
  const Eigen::Matrix3d to_index = volume.directions.inverse();
  const Eigen::Vector3d step_c = to_index * slice.right, step_r = to_index * slice.down;
  const Eigen::Vector3d start = to_index * (slice.origin - volume.origin);
  for (int r = 0; r < slice.height; ++r)
    for (int c = 0; c < slice.width; ++c)
      out[static_cast<size_t>(r) * slice.width + c] =
          static_cast<float>(at_index(volume, start + c * step_c + r * step_r));
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
