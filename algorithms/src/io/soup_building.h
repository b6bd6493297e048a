#pragma once
// Private: building triangle soups, shared by the mesh readers and the CT import — polygons
// fan-triangulated with their indices checked, and VTK polydata to and from soups.
#include <vtkSmartPointer.h>

#include <string>
#include <vector>

#include "cranioplan/model/mesh.h"

class vtkPolyData;

namespace cranioplan::detail {

/// Appends `poly` (0-based vertex indices) fan-triangulated to `tris`. Throws InputError when
/// an index is outside [0, nv); `what` and `number` name the face in the message ("face on
/// line", 12).
void add_polygon(const std::string& path, const std::vector<int>& poly, int nv,
                 std::vector<Eigen::Vector3i>& tris, const char* what, long long number);

/// The points and the polygons (fan-triangulated, indices checked: `path` names the file in the
/// message) and triangle strips of `pd`; an empty soup without points.
TriangleSoup soup_from_polydata(const std::string& path, vtkPolyData* pd);

/// A polydata of the soup's triangles, its points in double precision.
vtkSmartPointer<vtkPolyData> polydata_from_soup(const TriangleSoup& soup);

}  // namespace cranioplan::detail
