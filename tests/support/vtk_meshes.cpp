#include "support/vtk_meshes.h"

#include <vtkCellArray.h>
#include <vtkNew.h>
#include <vtkPoints.h>

namespace cranioplan::test {

vtkSmartPointer<vtkPolyData> to_polydata(const SkullMesh& mesh) {
  vtkNew<vtkPoints> points;
  points->SetDataTypeToDouble();
  for (auto vh : mesh.vertices()) {
    const auto& p = mesh.point(vh);
    points->InsertNextPoint(p[0], p[1], p[2]);
  }
  vtkNew<vtkCellArray> polys;
  for (auto fh : mesh.faces()) {
    vtkIdType ids[3];
    int k = 0;
    for (auto vh : mesh.fv_range(fh)) ids[k++] = vh.idx();
    polys->InsertNextCell(3, ids);
  }
  auto pd = vtkSmartPointer<vtkPolyData>::New();
  pd->SetPoints(points);
  pd->SetPolys(polys);
  return pd;
}

}  // namespace cranioplan::test
