#pragma once
// Rigid registration of the mirrored skull onto the original: point-to-plane ICP, trimmed and
// robust so the defect and its mirrored twin do not pull, optionally in a region of interest.
#include <optional>
#include <string>

#include "cranioplan/model/mesh.h"
#include "cranioplan/model/param_spec.h"
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

// The scalar fields' ranges and units are declared in for_each_field below.
struct RegisterParams {
  RigidTransform initial;               ///< starting transform of MOVING
  int sample_count = 6000;              ///< moving samples used
  int max_iterations = 60;              ///< updates at most
  double max_correspondence_mm = 8.0;   ///< pairs farther apart are ignored
  double trim_fraction = 0.85;          ///< keep this best fraction of pairs
  double huber_mm = 1.0;                ///< Huber weight scale for residuals
  double convergence_mm = 0.01;         ///< stop when an update moves no sample more than this
  std::optional<RegionOfInterest> roi;  ///< only moving samples inside it (after transform)
};

/// RegisterParams' scalar fields, each declared once (ParamSpec), in the order a session writes
/// them (the starting transform and the region follow them).
template <class Visit>
void for_each_field(Visit&& visit, RegisterParams& p) {
  visit(number("sample_count", "number of samples", 100, 200000), p.sample_count);
  visit(number("max_iterations", "number of updates", 1, 500), p.max_iterations);
  visit(length_mm("max_correspondence_mm", "largest pairing distance", 0.1, 100),
        p.max_correspondence_mm);
  visit(number("trim_fraction", "share of pairs kept", 0.05, 1), p.trim_fraction);
  visit(length_mm("huber_mm", "Huber scale", 0.01, 50), p.huber_mm);
  visit(length_mm("convergence_mm", "convergence distance", 0, 10), p.convergence_mm);
}

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
