#pragma once
#include <Eigen/Core>

#include "cranioplan/model/mesh.h"

namespace cranioplan {

struct MeshReport {
  long long vertices = 0;
  long long triangles = 0;
  Eigen::Vector3d bbox_min = Eigen::Vector3d::Zero();  ///< mm
  Eigen::Vector3d bbox_max = Eigen::Vector3d::Zero();  ///< mm
  double area_mm2 = 0.0;
  double volume_mm3 = 0.0;          ///< signed: positive for closed outward-oriented meshes
  long long boundary_edges = 0;     ///< edges with one triangle (after welding equal points)
  long long nonmanifold_edges = 0;  ///< edges with three or more triangles
  long long pieces = 0;             ///< connected pieces
  bool watertight = false;          ///< no boundary and no non-manifold edge
};

/// Counts and measures a mesh. Vertices at identical positions are treated as one, so edges a
/// reader split to keep OpenMesh manifold are still reported as non-manifold.
MeshReport report_mesh(const SkullMesh& mesh);

}  // namespace cranioplan
