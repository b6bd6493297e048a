#include "cranioplan/algorithms/surface_locator.h"

#include <vtkCellArray.h>
#include <vtkGenericCell.h>
#include <vtkNew.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkSmartPointer.h>
#include <vtkStaticCellLocator.h>

#include <Eigen/Geometry>
#include <cassert>
#include <cmath>

namespace cranioplan {

struct SurfaceLocator::Impl {
  vtkSmartPointer<vtkPolyData> polydata;
  vtkSmartPointer<vtkStaticCellLocator> locator;
  vtkSmartPointer<vtkGenericCell> cell;  // scratch for queries (one per locator)
  std::vector<Eigen::Vector3d> normals;
};

SurfaceLocator::SurfaceLocator(const SkullMesh& mesh) : impl_(std::make_unique<Impl>()) {
  assert(mesh.n_faces() > 0 && "SurfaceLocator needs a mesh with faces");
  vtkNew<vtkPoints> points;
  points->SetDataTypeToDouble();
  points->SetNumberOfPoints(static_cast<vtkIdType>(mesh.n_vertices()));
  for (auto vh : mesh.vertices()) points->SetPoint(vh.idx(), mesh.point(vh).data());
  vtkNew<vtkCellArray> polys;
  polys->AllocateExact(static_cast<vtkIdType>(mesh.n_faces()),
                       static_cast<vtkIdType>(mesh.n_faces()) * 3);
  impl_->normals.reserve(mesh.n_faces());
  for (auto fh : mesh.faces()) {
    vtkIdType ids[3];
    Eigen::Vector3d p[3];
    int k = 0;
    for (auto vh : mesh.fv_range(fh)) {
      ids[k] = vh.idx();
      p[k++] = to_eigen(mesh.point(vh));
    }
    polys->InsertNextCell(3, ids);
    const Eigen::Vector3d n = (p[1] - p[0]).cross(p[2] - p[0]);
    impl_->normals.push_back(n.norm() > 0 ? Eigen::Vector3d(n.normalized())
                                          : Eigen::Vector3d::Zero());
  }
  impl_->polydata = vtkSmartPointer<vtkPolyData>::New();
  impl_->polydata->SetPoints(points);
  impl_->polydata->SetPolys(polys);
  impl_->locator = vtkSmartPointer<vtkStaticCellLocator>::New();
  impl_->locator->SetDataSet(impl_->polydata);
  impl_->locator->SetNumberOfCellsPerNode(16);
  impl_->locator->BuildLocator();
  impl_->cell = vtkSmartPointer<vtkGenericCell>::New();
}

SurfaceLocator::~SurfaceLocator() = default;
SurfaceLocator::SurfaceLocator(SurfaceLocator&&) noexcept = default;
SurfaceLocator& SurfaceLocator::operator=(SurfaceLocator&&) noexcept = default;

SurfaceLocator::Closest SurfaceLocator::closest(const Eigen::Vector3d& query) const {
  double x[3] = {query.x(), query.y(), query.z()}, closest[3], d2 = 0;
  vtkIdType cell_id = -1;
  int sub_id = 0;
  impl_->locator->FindClosestPoint(x, closest, impl_->cell, cell_id, sub_id, d2);
  Closest c;
  c.point = {closest[0], closest[1], closest[2]};
  c.face = static_cast<int>(cell_id);
  c.distance = std::sqrt(d2);
  return c;
}

std::optional<SurfaceLocator::Hit> SurfaceLocator::first_hit(const Eigen::Vector3d& from,
                                                             const Eigen::Vector3d& to) const {
  double p1[3] = {from.x(), from.y(), from.z()}, p2[3] = {to.x(), to.y(), to.z()};
  double t = 0, x[3], pcoords[3];
  int sub_id = 0;
  vtkIdType cell_id = -1;
  if (!impl_->locator->IntersectWithLine(p1, p2, 0.0, t, x, pcoords, sub_id, cell_id, impl_->cell))
    return std::nullopt;
  Hit h;
  h.point = {x[0], x[1], x[2]};
  h.face = static_cast<int>(cell_id);
  h.distance = (h.point - from).norm();
  return h;
}

Eigen::Vector3d SurfaceLocator::face_normal(int face) const { return impl_->normals[face]; }

}  // namespace cranioplan
