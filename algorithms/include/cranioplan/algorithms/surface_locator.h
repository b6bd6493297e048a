#pragma once
// Closest points on, and ray hits with, a triangle mesh (VTK's static cell locator stays
// private). Built once per mesh. Queries share scratch space: one thread at a time.
#include <Eigen/Core>
#include <memory>
#include <optional>

#include "cranioplan/model/mesh.h"

namespace cranioplan {

class SurfaceLocator {
 public:
  explicit SurfaceLocator(const SkullMesh& mesh);
  ~SurfaceLocator();
  SurfaceLocator(SurfaceLocator&&) noexcept;
  SurfaceLocator& operator=(SurfaceLocator&&) noexcept;

  struct Closest {
    Eigen::Vector3d point;  ///< closest point on the surface, mm
    int face = -1;          ///< face index of the mesh
    double distance = 0.0;  ///< mm
  };
  /// Closest point on the surface. Requires a mesh with at least one face.
  Closest closest(const Eigen::Vector3d& query) const;

  struct Hit {
    Eigen::Vector3d point;
    int face = -1;
    double distance = 0.0;  ///< from the segment's start, mm
  };
  /// First intersection of the segment from `from` to `to` with the surface, if any.
  std::optional<Hit> first_hit(const Eigen::Vector3d& from, const Eigen::Vector3d& to) const;

  /// Unit normal of face `face` (counter-clockwise orientation).
  Eigen::Vector3d face_normal(int face) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace cranioplan
