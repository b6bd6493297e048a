#pragma once
// Closest points on, and segment hits with, a triangle mesh: a bounding-volume hierarchy over
// the faces (float boxes rounded outward, double-precision geometry), built once per mesh.
// Queries are const and keep no scratch space, so threads may share a locator.
#include <Eigen/Core>
#include <memory>
#include <optional>
#include <vector>

#include "cranioplan/model/mesh.h"
#include "cranioplan/model/rigid_transform.h"

namespace cranioplan {

class SurfaceLocator {
 public:
  explicit SurfaceLocator(const SkullMesh& mesh);
  ~SurfaceLocator();
  SurfaceLocator(const SurfaceLocator&);
  SurfaceLocator& operator=(const SurfaceLocator&);
  SurfaceLocator(SurfaceLocator&&) noexcept;
  SurfaceLocator& operator=(SurfaceLocator&&) noexcept;

  /// The same surface moved by `motion`, sharing this locator's tree (nothing is copied): the
  /// locator of a mirrored and registered skull is its skull's locator moved. `motion` must be
  /// an isometry; a reflection is allowed for meshes whose faces were reversed with it (as
  /// mirror_mesh() does), so that outward normals stay outward. Face indices are the original's.
  SurfaceLocator moved(const RigidTransform& motion) const;

  struct Closest {
    Eigen::Vector3d point;  ///< closest point on the surface, mm
    int face = -1;          ///< face index of the mesh
    double distance = 0.0;  ///< mm
  };
  /// Closest point on the surface. Requires a mesh with at least one face.
  Closest closest(const Eigen::Vector3d& query) const;
  /// The same when the surface comes nearer than `radius` mm, else nothing: the same distance
  /// (and, but among points exactly as near, the same point), found faster when the surface is
  /// mostly farther.
  std::optional<Closest> closest_within(const Eigen::Vector3d& query, double radius) const;
  /// The faces that come within `reach` mm of the box [lo, hi] (every face nearer than that to
  /// some point in it, and some farther), into `faces` (cleared first): for many queries from
  /// points in the box, found once. The box may be unbounded along an axis (±infinity).
  void faces_near(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi, double reach,
                  std::vector<int>& faces) const;
  /// closest_within() among `faces` only: the same distance when they hold every face within
  /// `radius` of `query` (faces_near() of a box holding it, with a reach of at least `radius`),
  /// and among points exactly as near perhaps another point.
  std::optional<Closest> closest_within(const Eigen::Vector3d& query, double radius,
                                        const std::vector<int>& faces) const;

  struct Hit {
    Eigen::Vector3d point;
    int face = -1;
    double distance = 0.0;  ///< from the segment's start, mm
  };
  /// First intersection of the segment from `from` to `to` with the surface, if any.
  std::optional<Hit> first_hit(const Eigen::Vector3d& from, const Eigen::Vector3d& to) const;
  /// Every intersection of the segment with the surface, in order along it (each found from
  /// 1e-4 mm past the one before; distances from `from`): for a closed surface, a point lies
  /// inside when a segment from it to a point outside crosses an odd number of times.
  std::vector<Hit> hits_along(const Eigen::Vector3d& from, const Eigen::Vector3d& to) const;

  /// Unit normal of face `face` (counter-clockwise orientation; zero for a degenerate face).
  Eigen::Vector3d face_normal(int face) const;

  /// Bytes held by the shared tree and geometry.
  size_t memory_bytes() const;

 private:
  struct Tree;
  SurfaceLocator(std::shared_ptr<const Tree> tree, const RigidTransform& motion, bool moved);
  std::shared_ptr<const Tree> tree_;
  RigidTransform motion_;  // world = motion_(tree coordinates)
  bool moved_ = false;
};

}  // namespace cranioplan
