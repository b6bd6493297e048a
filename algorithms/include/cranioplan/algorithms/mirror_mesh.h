#pragma once
#include "cranioplan/model/mesh.h"
#include "cranioplan/model/plane.h"

namespace cranioplan {

/// Reflects every vertex across the plane and reverses each face's orientation, so an
/// outward-oriented mesh stays outward-oriented (its signed volume keeps its sign). Vertex i of
/// the result is the mirror image of vertex i of the input.
SkullMesh mirror_mesh(const SkullMesh& mesh, const Plane& plane);

}  // namespace cranioplan
