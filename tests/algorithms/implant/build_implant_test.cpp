#include "cranioplan/algorithms/implant/build_implant.h"

#include <gtest/gtest.h>

#include "cranioplan/algorithms/geometry/surface_locator.h"
#include "cranioplan/algorithms/implant/snap_markers.h"
#include "cranioplan/algorithms/io/mesh_report.h"
#include "cranioplan/algorithms/quality/check_implant.h"
#include "cranioplan/algorithms/quality/compare_implants.h"
#include "cranioplan/algorithms/quality/inject_defect.h"
#include "support/synthetic.h"

namespace cranioplan {
namespace {

// A thick synthetic skull with a round defect, its true implant and the markers around it.
struct DefectCase {
  SkullMesh defective, truth;
  std::vector<Marker> markers;
};

const DefectCase& right_parietal_case() {
  static const DefectCase c = [] {
    DefectCase d;
    const SkullMesh skull = test::make_thick_head();
    const Eigen::Vector3d dir = Eigen::Vector3d(0.7, 0.1, 0.7).normalized();
    const Eigen::Vector3d center = test::head_surface_point(dir) * 0.965;
    InjectDefectParams p;
    p.center = center;
    p.size_mm = 50;
    p.voxel_mm = 0.5;
    const InjectDefectResult r = inject_defect(skull, p);
    d.defective = r.defective;
    d.truth = r.implant;
    d.markers = test::round_defect_markers(center, 25.0);
    const SurfaceLocator bone(d.defective);
    d.markers = snap_markers(d.markers, bone, nullptr, SnapMarkersParams{}).markers;
    return d;
  }();
  return c;
}

TEST(BuildImplant, ShellThroughMarkersIsWatertightAndPassesThroughEdgeMarkers) {
  const DefectCase& c = right_parietal_case();
  const ImplantResult r = build_implant(c.markers, &c.defective);
  ASSERT_TRUE(r.usable()) << r.message;
  EXPECT_TRUE(r.watertight);
  EXPECT_LT(r.rim_marker_error_mm, 0.05);
  const MeshReport rep = report_mesh(r.mesh);
  EXPECT_EQ(rep.pieces, 1);
  EXPECT_GT(rep.volume_mm3, 0);
  // Every edge marker is a vertex of the implant (within 0.05 mm).
  const SurfaceLocator implant(r.mesh);
  for (const auto& m : c.markers)
    if (is_edge(m.type)) {
      EXPECT_LT(implant.closest(m.position).distance, 0.05) << m.id;
    }
}

TEST(BuildImplant, ShellMatchesTheRemovedBone) {
  const DefectCase& c = right_parietal_case();
  const ImplantResult r = build_implant(c.markers, &c.defective);
  ASSERT_TRUE(r.usable()) << r.message;
  const CompareResult cmp = compare_implants(r.mesh, c.truth, &c.defective);
  EXPECT_GT(cmp.dice, 0.85) << "hd95 " << cmp.hd95_mm;
  EXPECT_LT(cmp.hd95_mm, 1.5);
  const QualityReport q = check_implant(r.mesh, &c.defective);
  EXPECT_TRUE(q.watertight);
  EXPECT_EQ(q.self_intersections, 0);
  EXPECT_LT(q.rim_gap_mm, 0.5);
  EXPECT_LT(q.penetration_mm3, 50.0);
}

TEST(BuildImplant, WithoutInnerMarkersTheShellIsOffsetByTheMeasuredBoneThickness) {
  const DefectCase& c = right_parietal_case();
  std::vector<Marker> outer_only;
  for (const auto& m : c.markers)
    if (is_outer(m.type)) outer_only.push_back(m);
  const ImplantResult r = build_implant(outer_only, &c.defective);
  ASSERT_TRUE(r.usable()) << r.message;
  EXPECT_TRUE(r.watertight);
  // The head wall is 7 % of a radius of ~75 mm: about 5 mm.
  EXPECT_GT(r.thickness_used_mm, 3.5);
  EXPECT_LT(r.thickness_used_mm, 7.0);
  EXPECT_GT(compare_implants(r.mesh, c.truth).dice, 0.75);
}

TEST(BuildImplant, Delaunay3dOverTheMarkers) {
  const DefectCase& c = right_parietal_case();
  ImplantParams p;
  p.method = ImplantMethod::Delaunay3D;
  const ImplantResult r = build_implant(c.markers, &c.defective, p);
  ASSERT_TRUE(r.usable()) << r.message;
  EXPECT_TRUE(r.watertight);  // alpha 0: the convex hull
  EXPECT_GT(report_mesh(r.mesh).volume_mm3, 0);
}

TEST(BuildImplant, TooFewMarkersGiveAStatus) {
  const std::vector<Marker> two = {{1, MarkerType::OuterEdge, {0, 0, 0}, MarkerSurface::Original},
                                   {2, MarkerType::OuterEdge, {1, 0, 0}, MarkerSurface::Original}};
  const ImplantResult r = build_implant(two, nullptr);
  EXPECT_EQ(r.status, ImplantResult::Status::TooFewMarkers);
  ImplantParams p;
  p.method = ImplantMethod::Delaunay3D;
  EXPECT_EQ(build_implant(two, nullptr, p).status, ImplantResult::Status::TooFewMarkers);
}

}  // namespace
}  // namespace cranioplan

namespace cranioplan {
namespace {

// A marker dragged through the opening onto the far wall of the skull must give a clear
// failure, not a runaway computation.
TEST(BuildImplant, AMarkerOnTheFarSideIsRefusedNotStretched) {
  const SkullMesh head = test::make_symmetric_head(4);
  const Eigen::Vector3d c = test::head_surface_point(Eigen::Vector3d(0.7, 0.1, 0.7).normalized());
  std::vector<Marker> markers = test::round_defect_markers(c * 0.965, 20.0);
  ASSERT_GT(markers.size(), 3u);
  markers.front().position = -markers.front().position;  // through the skull to the far side
  ImplantParams p;
  p.radial_center = Eigen::Vector3d::Zero();
  const ImplantResult r = build_implant(markers, &head, p);
  EXPECT_EQ(r.status, ImplantResult::Status::Failed);
  EXPECT_NE(r.message.find("far side"), std::string::npos) << r.message;
}

}  // namespace
}  // namespace cranioplan
