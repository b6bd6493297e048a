#pragma once
// Rigid registration of the mirrored skull onto the original: point-to-plane ICP, trimmed and
// robust so the defect and its mirrored twin do not pull, optionally in a region of interest.
#include <optional>
#include <string>

#include "cranioplan/model/mesh.h"
#include "cranioplan/model/plane.h"
#include "cranioplan/model/rigid_transform.h"

namespace cranioplan {

/// A region of interest in the fixed mesh's coordinates: a sphere, or an axis-aligned box.
struct RegionOfInterest {
  enum class Shape { Sphere, Box };
  Shape shape = Shape::Sphere;
  Eigen::Vector3d center = Eigen::Vector3d::Zero();           ///< mm
  double radius = 50.0;                                       ///< sphere radius, mm (>0)
  Eigen::Vector3d half_size = Eigen::Vector3d::Constant(50);  ///< box half extents, mm (>0)
  bool contains(const Eigen::Vector3d& p) const;
};

struct RegisterParams {
  RigidTransform initial;               ///< starting transform of MOVING
  int sample_count = 6000;              ///< moving samples used, 100..200000
  int max_iterations = 60;              ///< 1..500
  double max_correspondence_mm = 8.0;   ///< pairs farther apart are ignored, mm (>0)
  double trim_fraction = 0.85;          ///< keep this best fraction of pairs, (0, 1]
  double huber_mm = 1.0;                ///< Huber weight scale for residuals, mm (>0)
  double convergence_mm = 0.01;         ///< stop when an update moves no sample more than this, mm
  std::optional<RegionOfInterest> roi;  ///< only moving samples inside it (after transform)
};

struct RegisterResult {
  enum class Status { Converged, MaxIterations, Failed };
  Status status = Status::Failed;
  std::string message;
  RigidTransform transform;      ///< x ↦ R·x + t carrying MOVING onto FIXED
  double rms_mm = 0.0;           ///< point-to-plane RMS over the pairs kept in the last step
  double inlier_fraction = 0.0;  ///< pairs kept / samples considered
  int iterations = 0;
  double seconds = 0.0;
  bool usable() const { return status != Status::Failed; }
};

struct VertexCloud;

/// `fixed_cloud` and `moving_cloud`, when given, are the meshes' VertexCloud made beforehand
/// (the same result, without making them again).
RegisterResult register_icp(const SkullMesh& moving, const SkullMesh& fixed,
                            const RegisterParams& params = {},
                            const VertexCloud* fixed_cloud = nullptr,
                            const VertexCloud* moving_cloud = nullptr);

/// Registers the skull's mirror image across `plane` onto the skull without building the mirrored
/// mesh (a copy as large as the skull: docs/BENCHMARKS.md, "Where the memory goes, and what
/// bounds it"): the skull is registered onto itself starting from `params.initial` after the
/// reflection. The result carries the mirror (mirror_mesh(skull, plane)) onto the skull, as
/// register_icp(mirror, skull, params) does.
RegisterResult register_mirror(const SkullMesh& skull, const Plane& plane,
                               const RegisterParams& params = {},
                               const VertexCloud* cloud = nullptr);

/// A copy of the mesh with every vertex transformed.
SkullMesh transform_mesh(const SkullMesh& mesh, const RigidTransform& transform);

}  // namespace cranioplan
