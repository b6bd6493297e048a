#include "io/soup_building.h"

#include <gtest/gtest.h>
#include <vtkCellArray.h>
#include <vtkNew.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>

#include "cranioplan/model/error.h"

namespace cranioplan {
namespace {

TEST(SoupBuilding, PolygonsAreFannedAndBadIndicesNamed) {
  std::vector<Eigen::Vector3i> tris;
  detail::add_polygon("q.obj", {0, 1, 2, 3, 4}, 5, tris, "face on line", 9);
  ASSERT_EQ(tris.size(), 3u);
  EXPECT_EQ(tris[0], Eigen::Vector3i(0, 1, 2));
  EXPECT_EQ(tris[2], Eigen::Vector3i(0, 3, 4));
  try {
    detail::add_polygon("q.off", {0, 1, 5000}, 1200, tris, "face", 12345);
    ADD_FAILURE();
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(),
                 "q.off: face 12,345 uses vertex 5000 but the file has 1,200 vertices (numbered "
                 "from 0)");
  }
  EXPECT_EQ(tris.size(), 3u) << "nothing of a bad polygon is added";
}

// Polygons are fanned, strips unrolled with every other triangle turned back, points kept in
// double precision both ways.
TEST(SoupBuilding, PolydataToSoupAndBack) {
  vtkNew<vtkPoints> pts;
  pts->SetDataTypeToDouble();
  for (int i = 0; i < 6; ++i) pts->InsertNextPoint(i, i % 2, 0.1 + 1e-12 * i);
  vtkNew<vtkCellArray> polys, strips;
  const vtkIdType quad[4] = {0, 1, 3, 2};
  polys->InsertNextCell(4, quad);
  const vtkIdType strip[5] = {1, 2, 3, 4, 5};
  strips->InsertNextCell(5, strip);
  vtkNew<vtkPolyData> pd;
  pd->SetPoints(pts);
  pd->SetPolys(polys);
  pd->SetStrips(strips);
  const TriangleSoup soup = detail::soup_from_polydata("x.vtp", pd);
  ASSERT_EQ(soup.triangles.size(), 5u);
  EXPECT_EQ(soup.triangles[1], Eigen::Vector3i(0, 3, 2));
  EXPECT_EQ(soup.triangles[2], Eigen::Vector3i(1, 2, 3));
  EXPECT_EQ(soup.triangles[3], Eigen::Vector3i(3, 2, 4)) << "the strip's second turned back";
  EXPECT_EQ(soup.vertices[5].z(), 0.1 + 1e-12 * 5);

  const vtkSmartPointer<vtkPolyData> back = detail::polydata_from_soup(soup);
  EXPECT_EQ(back->GetNumberOfPolys(), 5);
  const TriangleSoup again = detail::soup_from_polydata("y.vtp", back);
  EXPECT_EQ(again.vertices, soup.vertices);
  EXPECT_EQ(again.triangles, soup.triangles);
  EXPECT_TRUE(detail::soup_from_polydata("z.vtp", nullptr).triangles.empty());
}

}  // namespace
}  // namespace cranioplan
