#include "soup_building.h"

#include <vtkCellArray.h>
#include <vtkIdList.h>
#include <vtkNew.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>

#include "cranioplan/model/error.h"

namespace cranioplan::detail {

void add_polygon(const std::string& path, const std::vector<int>& poly, int nv,
                 std::vector<Eigen::Vector3i>& tris, const char* what, long long number) {
  for (int idx : poly)
    if (idx < 0 || idx >= nv)
      throw InputError(path, what + (" " + format_count(number)) + " uses vertex " +
                                 std::to_string(idx) + " but the file has " + format_count(nv) +
                                 " vertices (numbered from 0)");
  for (size_t k = 1; k + 1 < poly.size(); ++k) tris.emplace_back(poly[0], poly[k], poly[k + 1]);
}

TriangleSoup soup_from_polydata(const std::string& path, vtkPolyData* pd) {
  TriangleSoup soup;
  if (!pd || !pd->GetPoints()) return soup;
  const vtkIdType np = pd->GetNumberOfPoints();
  soup.vertices.resize(static_cast<size_t>(np));
  for (vtkIdType i = 0; i < np; ++i) {
    double p[3];
    pd->GetPoint(i, p);
    soup.vertices[static_cast<size_t>(i)] = {p[0], p[1], p[2]};
  }
  std::vector<int> poly;
  vtkCellArray* cells = pd->GetPolys();
  soup.triangles.reserve(static_cast<size_t>(cells->GetNumberOfCells()));
  vtkNew<vtkIdList> ids;
  long long cell = 0;
  for (cells->InitTraversal(); cells->GetNextCell(ids);) {
    poly.assign(ids->begin(), ids->end());
    if (poly.size() >= 3)
      add_polygon(path, poly, static_cast<int>(np), soup.triangles, "polygon", ++cell);
  }
  vtkCellArray* strips = pd->GetStrips();
  for (strips->InitTraversal(); strips->GetNextCell(ids);)
    for (vtkIdType k = 0; k + 2 < ids->GetNumberOfIds(); ++k) {
      const int a = static_cast<int>(ids->GetId(k)), b = static_cast<int>(ids->GetId(k + 1)),
                c = static_cast<int>(ids->GetId(k + 2));
      soup.triangles.push_back(k % 2 == 0 ? Eigen::Vector3i(a, b, c) : Eigen::Vector3i(b, a, c));
    }
  return soup;
}

vtkSmartPointer<vtkPolyData> polydata_from_soup(const TriangleSoup& soup) {
  vtkNew<vtkPoints> pts;
  pts->SetDataTypeToDouble();
  pts->SetNumberOfPoints(static_cast<vtkIdType>(soup.vertices.size()));
  for (size_t i = 0; i < soup.vertices.size(); ++i)
    pts->SetPoint(static_cast<vtkIdType>(i), soup.vertices[i].data());
  vtkNew<vtkCellArray> polys;
  polys->AllocateExact(static_cast<vtkIdType>(soup.triangles.size()),
                       static_cast<vtkIdType>(soup.triangles.size() * 3));
  for (const auto& t : soup.triangles) {
    const vtkIdType ids[3] = {t[0], t[1], t[2]};
    polys->InsertNextCell(3, ids);
  }
  auto pd = vtkSmartPointer<vtkPolyData>::New();
  pd->SetPoints(pts);
  pd->SetPolys(polys);
  return pd;
}

}  // namespace cranioplan::detail
