#pragma once
#include "cranioplan/model/mesh.h"

namespace cranioplan {

/// Number of pairs of triangles that cross each other (pairs sharing a vertex are not tested).
long long count_self_intersections(const SkullMesh& mesh);

}  // namespace cranioplan
