#include "cranioplan/algorithms/geometry/surface_samples.h"

#include <Eigen/Geometry>
#include <cmath>
#include <numeric>
#include <random>

namespace cranioplan {

std::vector<Eigen::Vector3d> vertex_normals(const SkullMesh& mesh) {
  std::vector<Eigen::Vector3d> normals(mesh.n_vertices(), Eigen::Vector3d::Zero());
  for (auto fh : mesh.faces()) {
    const FaceCorners f = face_corners(mesh, fh);
    const Eigen::Vector3d n = f.cross();  // length = 2·area
    for (int i : f.ids) normals[i] += n;
  }
  for (auto& n : normals) {
    const double len = n.norm();
    if (len > 0) n /= len;
  }
  return normals;
}

SurfaceSamples all_vertex_samples(const SkullMesh& mesh) {
  SurfaceSamples s;
  s.normals = vertex_normals(mesh);
  s.points.reserve(mesh.n_vertices());
  for (auto vh : mesh.vertices()) s.points.push_back(to_eigen(mesh.point(vh)));
  return s;
}

SurfaceSamples subsample(const SurfaceSamples& samples, size_t max_count) {
  if (samples.points.size() <= max_count) return samples;
  std::vector<size_t> order(samples.points.size());
  std::iota(order.begin(), order.end(), 0);
  std::mt19937 rng(12345);  // fixed seed: the same mesh always gives the same samples
  std::shuffle(order.begin(), order.end(), rng);
  SurfaceSamples out;
  out.points.reserve(max_count);
  out.normals.reserve(max_count);
  for (size_t i = 0; i < max_count; ++i) {
    out.points.push_back(samples.points[order[i]]);
    out.normals.push_back(samples.normals[order[i]]);
  }
  return out;
}

std::vector<Eigen::Vector3d> fibonacci_sphere(int n) {
  std::vector<Eigen::Vector3d> d(n);
  const double golden = M_PI * (3.0 - std::sqrt(5.0));
  for (int i = 0; i < n; ++i) {
    const double z = 1.0 - 2.0 * (i + 0.5) / n, r = std::sqrt(1.0 - z * z), a = golden * i;
    d[i] = {r * std::cos(a), r * std::sin(a), z};
  }
  return d;
}

}  // namespace cranioplan
