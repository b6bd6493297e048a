#pragma once
// Nearest-neighbour queries over a fixed set of points (a k-d tree; nanoflann stays private).
#include <Eigen/Core>
#include <memory>
#include <vector>

#include "cranioplan/algorithms/geometry/surface_samples.h"

namespace cranioplan {

class PointIndex {
 public:
  explicit PointIndex(std::vector<Eigen::Vector3d> points);
  ~PointIndex();
  PointIndex(PointIndex&&) noexcept;
  PointIndex& operator=(PointIndex&&) noexcept;

  /// Index of the nearest point and its squared distance (mm²). Requires a non-empty set.
  int nearest(const Eigen::Vector3d& query, double* squared_distance = nullptr) const;
  /// Indices of all points within `radius` mm.
  std::vector<int> within_radius(const Eigen::Vector3d& query, double radius) const;
  const std::vector<Eigen::Vector3d>& points() const;
  size_t size() const { return points().size(); }

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// Greedy thinning: indices of the points kept, in the given order, each at least `spacing` mm
/// from every point kept before it (earlier points win).
std::vector<size_t> thin_points(const std::vector<Eigen::Vector3d>& points, double spacing);

/// A mesh's vertices with their normals (all_vertex_samples) and a search tree over them, made
/// once and shared by the stages that each need them (the plane fit, the registrations): on a
/// large skull each is dear to make (docs/decisions/0028-speed-history.md).
struct VertexCloud {
  explicit VertexCloud(const SkullMesh& mesh);
  SurfaceSamples samples;
  PointIndex index;
};

}  // namespace cranioplan
