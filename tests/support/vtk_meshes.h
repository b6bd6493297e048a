#pragma once
// Test meshes handed to VTK's own filters and writers, as other programs make their files.
#include <vtkPolyData.h>
#include <vtkSmartPointer.h>

#include "cranioplan/model/mesh.h"

namespace cranioplan::test {

/// The mesh as VTK polydata (double points, one triangle per face, in the mesh's order).
vtkSmartPointer<vtkPolyData> to_polydata(const SkullMesh& mesh);

}  // namespace cranioplan::test
