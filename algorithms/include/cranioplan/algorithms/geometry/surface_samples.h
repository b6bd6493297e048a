#pragma once
// Oriented sample points of a mesh surface (vertices with area-weighted normals).
#include <Eigen/Core>
#include <vector>

#include "cranioplan/model/mesh.h"

namespace cranioplan {

struct SurfaceSamples {
  std::vector<Eigen::Vector3d> points;
  std::vector<Eigen::Vector3d> normals;  ///< unit, outward for an outward-oriented mesh
};

/// Area-weighted unit vertex normals, one per vertex (zero for isolated vertices).
std::vector<Eigen::Vector3d> vertex_normals(const SkullMesh& mesh);

/// All vertices with their normals.
SurfaceSamples all_vertex_samples(const SkullMesh& mesh);

/// At most `max_count` vertices, chosen on a regular stride through a fixed permutation so the
/// result is deterministic and spread over the whole surface.
SurfaceSamples subsample(const SurfaceSamples& samples, size_t max_count);

/// `n` directions spread evenly over the unit sphere (a Fibonacci lattice).
std::vector<Eigen::Vector3d> fibonacci_sphere(int n);

}  // namespace cranioplan
