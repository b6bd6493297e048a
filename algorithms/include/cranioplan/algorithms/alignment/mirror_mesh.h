#pragma once
#include "cranioplan/model/mesh.h"
#include "cranioplan/model/plane.h"
#include "cranioplan/model/rigid_transform.h"

namespace cranioplan {

/// Reflects every vertex across the plane and reverses each face's orientation, so an
/// outward-oriented mesh stays outward-oriented (its signed volume keeps its sign). Vertex i of
/// the result is the mirror image of vertex i of the input.
SkullMesh mirror_mesh(const SkullMesh& mesh, const Plane& plane);

/// The reflection across the plane as a transform (an improper one: its rotation part has
/// determinant −1). mirror_mesh(mesh, plane) is the mesh moved by it, with faces reversed; a
/// locator of the mesh moved by it (SurfaceLocator::moved) answers for the mirror.
RigidTransform reflection_across(const Plane& plane);

}  // namespace cranioplan
