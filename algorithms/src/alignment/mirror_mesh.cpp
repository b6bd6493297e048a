#include "cranioplan/algorithms/alignment/mirror_mesh.h"

namespace cranioplan {

SkullMesh mirror_mesh(const SkullMesh& mesh, const Plane& plane) {
  TriangleSoup soup = to_soup(mesh);
  for (auto& p : soup.vertices) p = plane.reflect(p);
  for (auto& t : soup.triangles) std::swap(t[1], t[2]);
  return build_mesh(soup);
}

RigidTransform reflection_across(const Plane& plane) {
  RigidTransform t;
  t.rotation = Eigen::Matrix3d::Identity() - 2.0 * plane.normal * plane.normal.transpose();
  t.translation = 2.0 * plane.offset * plane.normal;
  return t;
}

}  // namespace cranioplan
