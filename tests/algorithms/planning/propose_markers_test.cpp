#include "cranioplan/algorithms/planning/propose_markers.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <vector>

#include "cranioplan/algorithms/geometry/surface_locator.h"
#include "cranioplan/algorithms/planning/fit_defect_surfaces.h"
#include "cranioplan/algorithms/planning/shape_prior.h"
#include "cranioplan/algorithms/shape/correspond_skull.h"
#include "cranioplan/algorithms/shape/shape_model.h"
#include "support/synthetic.h"

namespace cranioplan {
namespace {

// The proposal for the synthetic defect with the intact head as a perfect mirror: the markers
// stand on the bone the truth has there.
TEST(ProposeMarkers, MarkersLieOnTheRimAndOnTheMissingBone) {
  const test::ThickHeadDefect& c = test::thick_head_defect();
  ASSERT_TRUE(c.defect.found()) << c.defect.message;
  const SurfaceLocator bone(c.defective), truth(c.intact);
  const MarkerProposal p = propose_markers_for_defect(c.defect, bone, truth, ProposeParams{}, 7);
  ASSERT_TRUE(p.proposed()) << p.message;
  EXPECT_EQ(p.method_used, PlanMethod::Mirror);
  EXPECT_GT(p.mirror_coverage, 0.9);
  std::map<MarkerType, int> count;
  for (size_t i = 0; i < p.markers.size(); ++i) {
    const Marker& m = p.markers[i];
    EXPECT_EQ(m.id, 7 + static_cast<int>(i)) << "ids from first_id on, in order";
    // Edge markers and the support markers beside the rim lie on the skull; surface markers
    // over the opening on the mirror, here the intact head.
    if (is_edge(m.type)) {
      EXPECT_EQ(m.surface, MarkerSurface::Original);
    }
    ++count[m.type];
    const SurfaceLocator& on = m.surface == MarkerSurface::Original ? bone : truth;
    EXPECT_LT(on.closest(m.position).distance, 1.0) << to_string(m.type) << " " << m.id;
  }
  EXPECT_GE(count[MarkerType::OuterEdge], 10);
  EXPECT_GE(count[MarkerType::OuterSurface], 10);
  EXPECT_GE(count[MarkerType::InnerSurface], 10);
}

// Mirror-guided where the mirror has no bone over part of the rim (its own opening, a sinus):
// intact bone continues beyond the rim there, but no fitted surface says where. The rim's last
// bone is still an edge marker, so the outline follows the rim there too instead of cutting
// straight across.
TEST(ProposeMarkers, TheRimKeepsEdgeMarkersWhereTheMirrorHasNoBone) {
  const test::ThickHeadDefect& c = test::thick_head_defect();
  ASSERT_TRUE(c.defect.found()) << c.defect.message;
  ASSERT_GT(c.defect.outer_rim.size(), 8u);
  const Eigen::Vector3d hole_at = c.defect.outer_rim.front();
  const Eigen::Vector3d inward = (test::head_surface_point(c.defect.axis) - hole_at).normalized();
  // The mirror's hole covers the rim there but not the intact bone 5-7 mm beyond it, where the
  // proposal looks for bone that goes on.
  const SkullMesh mirror_mesh = test::cut_hole(c.intact, hole_at + 8.0 * inward, 9.5);
  const SurfaceLocator bone(c.defective), mirror(mirror_mesh);
  ProposeParams params;
  params.method = PlanMethod::Mirror;
  const MarkerProposal p = propose_markers_for_defect(c.defect, bone, mirror, params);
  ASSERT_TRUE(p.proposed()) << p.message;
  std::vector<Eigen::Vector3d> edges;
  for (const Marker& m : p.markers)
    if (m.type == MarkerType::OuterEdge) edges.push_back(m.position);
  ASSERT_FALSE(edges.empty());
  // Every rim point has an edge marker within a marker spacing (4 mm); without the rim's last
  // bone as markers there, the rim point under the mirror's hole had none within 7.6 mm.
  int rim_in_hole = 0;
  for (const Eigen::Vector3d& r : c.defect.outer_rim) {
    double nearest = 1e9;
    for (const Eigen::Vector3d& e : edges) nearest = std::min(nearest, (e - r).norm());
    EXPECT_LT(nearest, params.edge_spacing_mm + 0.5) << r.transpose();
    rim_in_hole += (r - hole_at).norm() < 8.0;
  }
  EXPECT_GE(rim_in_hole, 2) << "the mirror's hole lies over a stretch of the rim";
  // Those edge markers lie on the skull's bone.
  for (const Eigen::Vector3d& e : edges) EXPECT_LT(bone.closest(e).distance, 1.0);
}

// An orbit beside the defect: a hole 24 mm across in both skulls, its edge 2.5 mm beyond a
// stretch of the rim, so no intact bone goes on beyond the rim there. Rim-only, the fit only
// extrapolates over such a stretch and its edge markers stand on the rim's last bone.
// Mirror-guided, the mirror has its own table there, and every edge marker stands on the
// fitted outer surface, as where bone goes on: where a ray grazes the rounded edge of the bone
// above a real orbit, the last bone it meets moves by millimetres with the rays' start.
TEST(ProposeMarkers, MirrorGuidedEdgeMarkersBesideAnOrbitStandOnTheMirrorsTable) {
  const test::ThickHeadDefect& c = test::thick_head_defect();
  ASSERT_TRUE(c.defect.found()) << c.defect.message;
  const Eigen::Vector3d rim = c.defect.outer_rim.front();
  const Eigen::Vector3d out = (rim - rim.dot(c.defect.axis) * c.defect.axis).normalized();
  constexpr double kOrbitRadius = 12.0, kBridge = 2.5;  // mm
  const Eigen::Vector3d orbit =
      test::head_surface_point((rim + (kOrbitRadius + kBridge) * out).normalized());
  const SkullMesh skull = test::cut_hole(c.defective, orbit, kOrbitRadius);
  const SkullMesh mirror_mesh = test::cut_hole(c.intact, orbit, kOrbitRadius);
  const SurfaceLocator bone(skull), mirror(mirror_mesh);
  const DefectRegion defect = detect_defect(skull, bone, Eigen::Vector3d::Zero());
  ASSERT_TRUE(defect.found()) << defect.message;
  ASSERT_LT(defect.area_mm2, 1.2 * c.defect.area_mm2) << "the defect, not the two together";
  auto at_rim = [&](const Eigen::Vector3d& p) {
    for (const Eigen::Vector3d& r : defect.outer_rim)
      if ((r - p).norm() < 1e-9) return true;
    return false;
  };

  ProposeParams rim_only;
  rim_only.method = PlanMethod::RimOnly;
  const MarkerProposal a = propose_markers_for_defect(defect, bone, mirror, rim_only);
  ASSERT_TRUE(a.proposed()) << a.message;
  int last_bone = 0;
  for (const Marker& m : a.markers)
    if (m.type == MarkerType::OuterEdge && at_rim(m.position)) {
      ++last_bone;
      EXPECT_LT((m.position - orbit).norm(), kOrbitRadius + 10.0) << "only beside the orbit";
    }
  EXPECT_GE(last_bone, 2) << "the stretch beside the orbit";

  ProposeParams guided;
  guided.method = PlanMethod::Mirror;
  const MarkerProposal b = propose_markers_for_defect(defect, bone, mirror, guided);
  ASSERT_TRUE(b.proposed()) << b.message;
  const DefectSurfaces fitted =
      fit_defect_surfaces(defect, bone, &mirror, guided.surfaces, guided.detect);
  ASSERT_TRUE(fitted.fitted()) << fitted.message;
  int beside_orbit = 0;
  for (const Marker& m : b.markers) {
    if (m.type != MarkerType::OuterEdge) continue;
    const auto on = fitted.at(m.position - defect.center);
    ASSERT_TRUE(on.has_value()) << "the mirror has bone along every rim point";
    EXPECT_LT((m.position - on->first).norm(), 1e-6) << "edge marker " << m.id;
    // There the fitted surface is the intact head's outer table (a perfect mirror).
    EXPECT_LT(mirror.closest(m.position).distance, 0.5) << "edge marker " << m.id;
    beside_orbit += (m.position - orbit).norm() < kOrbitRadius + 5.0;
  }
  EXPECT_GE(beside_orbit, 2);
}

TEST(ProposeMarkers, RimOnlyFittingIsUsedWhenAsked) {
  const test::ThickHeadDefect& c = test::thick_head_defect();
  const SurfaceLocator bone(c.defective), truth(c.intact);
  ProposeParams params;
  params.method = PlanMethod::RimOnly;
  const MarkerProposal p = propose_markers_for_defect(c.defect, bone, truth, params);
  ASSERT_TRUE(p.proposed()) << p.message;
  EXPECT_EQ(p.method_used, PlanMethod::RimOnly);
  // Without the mirror every marker is on the skull's side, and the surface markers still
  // follow the missing bone within 2 mm.
  for (const Marker& m : p.markers) {
    EXPECT_EQ(m.surface, MarkerSurface::Original);
    if (m.type == MarkerType::OuterSurface) {
      EXPECT_LT(truth.closest(m.position).distance, 2.0);
    }
  }
}

// A shape model is fitted only where it will guide the surfaces, and the proposal says which
// source shaped the opening. The model: the intact head itself, stretched three ways, so where
// it guides, the markers lie on the missing bone (known answer).
TEST(ProposeMarkers, AShapeModelIsFittedOnlyWhereItGuidesAndTheSourcesAreSaid) {
  const test::ThickHeadDefect& c = test::thick_head_defect();
  ASSERT_TRUE(c.defect.found()) << c.defect.message;
  const ShapeModel model = test::stretched_head_model(c.intact);
  ASSERT_GT(model.outer_count, 100);
  const SurfaceLocator bone(c.defective), truth(c.intact);

  // Auto with the mirror covering the opening: the mirror alone, the model not fitted.
  std::optional<ShapeFit> fit;
  const MarkerProposal mirrored = propose_markers_with_model(c.defect, c.defective, bone, truth,
                                                             ProposeParams{}, 1, &model, {}, &fit);
  ASSERT_TRUE(mirrored.proposed()) << mirrored.message;
  EXPECT_EQ(mirrored.method_used, PlanMethod::Mirror);
  ASSERT_TRUE(fit.has_value());
  EXPECT_EQ(fit->status, ShapeFit::Status::Skipped);
  EXPECT_NE(mirrored.surfaces_message.find("not fitted, the mirror covers"), std::string::npos)
      << mirrored.surfaces_message;
  EXPECT_GT(mirrored.sources.mirror, 0.9);
  EXPECT_EQ(mirrored.sources.ring, 0.0);
  EXPECT_EQ(mirrored.sources.with_model, 0.0);
  EXPECT_NEAR(mirrored.sources.mirror + mirrored.sources.none, 1.0, 1e-9);

  // Asked for the ring alone: not fitted either.
  ProposeParams rim_only;
  rim_only.method = PlanMethod::RimOnly;
  const MarkerProposal ring =
      propose_markers_with_model(c.defect, c.defective, bone, truth, rim_only, 1, &model, {}, &fit);
  ASSERT_TRUE(ring.proposed()) << ring.message;
  EXPECT_EQ(fit->status, ShapeFit::Status::Skipped);
  EXPECT_GT(ring.sources.ring, 0.9);
  EXPECT_EQ(ring.sources.with_model, 0.0);
  EXPECT_NE(ring.surfaces_message.find("100% ring fit;"), std::string::npos)
      << ring.surfaces_message;

  // Asked for the model: fitted (to the head it was made of) and averaged into the mirror's
  // surfaces over the whole opening; the markers stay on the missing bone.
  ProposeParams guided;
  guided.method = PlanMethod::ShapeModel;
  const MarkerProposal shaped =
      propose_markers_with_model(c.defect, c.defective, bone, truth, guided, 1, &model, {}, &fit);
  ASSERT_TRUE(shaped.proposed()) << shaped.message;
  ASSERT_TRUE(fit && fit->usable()) << (fit ? fit->message : "no fit");
  EXPECT_LT(fit->rms_mm, 0.5);
  EXPECT_EQ(shaped.method_used, PlanMethod::ShapeModel);
  EXPECT_GT(shaped.sources.with_model, 0.9);
  EXPECT_LE(shaped.sources.with_model, shaped.sources.mirror + 1e-9);
  EXPECT_NE(shaped.surfaces_message.find("mirror with the shape model"), std::string::npos)
      << shaped.surfaces_message;
  for (const Marker& m : shaped.markers) {
    if (m.type == MarkerType::OuterSurface) {
      EXPECT_LT(truth.closest(m.position).distance, 1.0);
    }
  }

  // Auto where the mirror does not cover the opening (its bone there cut away): the model is
  // fitted and guides the ring's surfaces, and the markers stay on the missing bone.
  const SkullMesh uncovered_mesh =
      test::cut_hole(c.intact, test::head_surface_point(c.defect.axis), 45.0);
  const SurfaceLocator uncovered(uncovered_mesh);
  const MarkerProposal modelled = propose_markers_with_model(c.defect, c.defective, bone, uncovered,
                                                             ProposeParams{}, 1, &model, {}, &fit);
  ASSERT_TRUE(modelled.proposed()) << modelled.message;
  EXPECT_LT(modelled.mirror_coverage, ProposeParams{}.min_mirror_coverage);
  EXPECT_EQ(modelled.method_used, PlanMethod::ShapeModel);
  ASSERT_TRUE(fit && fit->usable()) << (fit ? fit->message : "no fit");
  EXPECT_GT(modelled.sources.ring, 0.9);
  EXPECT_GT(modelled.sources.with_model, 0.8);
  EXPECT_NE(modelled.surfaces_message.find("ring fit with the shape model"), std::string::npos)
      << modelled.surfaces_message;
  for (const Marker& m : modelled.markers) {
    if (m.type == MarkerType::OuterSurface) {
      EXPECT_LT(truth.closest(m.position).distance, 1.0);
    }
  }

  // No model, no note.
  const MarkerProposal plain = propose_markers_with_model(c.defect, c.defective, bone, truth,
                                                          ProposeParams{}, 1, nullptr, {}, &fit);
  EXPECT_FALSE(fit.has_value());
  EXPECT_EQ(plain.surfaces_message.find("shape model"), std::string::npos);
}

// The sentence splits the model's share between the two sources in proportion.
TEST(ProposeMarkers, TheSourcesSentenceSplitsTheModelsShare) {
  SurfaceSources s;
  s.mirror = 0.6;
  s.with_model = 0.3;
  s.none = 0.4;
  EXPECT_EQ(s.describe(),
            "the opening's surfaces: 30% mirror with the shape model, 30% mirror alone, 40% "
            "bridged from the surfaces around (no value along those rays); edge markers on them "
            "along the rim, support markers on the skull's own bone");
  EXPECT_EQ(SurfaceSources{}.describe(),
            "the opening's surfaces: none; edge markers on them along the rim, support markers "
            "on the skull's own bone");
}

TEST(ProposeMarkers, AnIntactSkullHasNoDefectToPropose) {
  const test::ThickHeadDefect& c = test::thick_head_defect();
  const SurfaceLocator intact(c.intact);
  const MarkerProposal p =
      propose_markers(c.intact, intact, Plane::through({}, {1, 0, 0}), intact, ProposeParams{});
  EXPECT_EQ(p.status, MarkerProposal::Status::NoDefect) << p.message;
  EXPECT_TRUE(p.markers.empty());
}

TEST(ProposeMarkers, MethodsHaveNamesAndTheRegionReachesPastTheRim) {
  for (PlanMethod m : {PlanMethod::Auto, PlanMethod::Mirror, PlanMethod::RimOnly}) {
    PlanMethod back = PlanMethod::Auto;
    ASSERT_TRUE(plan_method_from_string(to_string(m), back)) << to_string(m);
    EXPECT_EQ(back, m);
  }
  PlanMethod unchanged = PlanMethod::Mirror;
  EXPECT_FALSE(plan_method_from_string("mirrored", unchanged));
  EXPECT_EQ(describe_method(PlanMethod::Mirror, 0.974),
            "mirror-guided (mirror covers 97% of the opening)");
  const DefectRegion& d = test::thick_head_defect().defect;
  const RegionOfInterest roi = local_registration_region(d, 20.0);
  for (const Eigen::Vector3d& p : d.outer_rim) EXPECT_LE((p - roi.center).norm(), roi.radius - 20);
}

// A bone chip lying on the outer table just beyond the rim (a fragment, like those below a
// frontal sinus): the rays through it meet it as their last bone, millimetres above the
// table. Support markers stand only on bone the fitted surface describes: none on the chip,
// where one would pull the implant's outer surface up to it, and whether a ray near the chip's
// edge counts would decide the implant's shape there. With the rule off, the chip gets some.
TEST(ProposeMarkers, SupportMarkersStayOffBoneTheFittedSurfaceDoesNotDescribe) {
  const test::ThickHeadDefect& c = test::thick_head_defect();
  ASSERT_TRUE(c.defect.found()) << c.defect.message;
  const Eigen::Vector3d rim = c.defect.outer_rim.front();
  Eigen::Vector3d out = rim - rim.dot(c.defect.axis) * c.defect.axis;  // away from the axis
  const Eigen::Vector3d d = (rim + 8.0 * out.normalized()).normalized();
  const Eigen::Vector3d chip_centre = test::head_surface_point(d) + 5.0 * d;
  const TriangleSoup chip = test::box_soup(chip_centre - Eigen::Vector3d::Constant(2.0),
                                           chip_centre + Eigen::Vector3d::Constant(2.0));
  TriangleSoup soup = to_soup(c.defective);
  const int first = static_cast<int>(soup.vertices.size());
  soup.vertices.insert(soup.vertices.end(), chip.vertices.begin(), chip.vertices.end());
  for (const Eigen::Vector3i& t : chip.triangles)
    soup.triangles.push_back(t + Eigen::Vector3i::Constant(first));
  const SkullMesh skull = build_mesh(soup);
  const SurfaceLocator bone(skull), truth(c.intact);
  const SurfaceLocator chip_bone(build_mesh(chip));
  const DefectRegion defect = detect_defect(skull, bone, Eigen::Vector3d::Zero());
  ASSERT_TRUE(defect.found()) << defect.message;

  auto on_chip = [&](const ProposeParams& params) {
    const MarkerProposal p = propose_markers_for_defect(defect, bone, truth, params);
    EXPECT_TRUE(p.proposed()) << p.message;
    int n = 0, support = 0;
    for (const Marker& m : p.markers) {
      if (is_edge(m.type) || m.surface != MarkerSurface::Original) continue;
      ++support;
      n += chip_bone.closest(m.position).distance < 0.5;
    }
    EXPECT_GE(support, 20);
    return n;
  };
  EXPECT_EQ(on_chip(ProposeParams{}), 0);
  ProposeParams off;
  off.max_support_off_fit_mm = 0.0;
  EXPECT_GE(on_chip(off), 1) << "the chip lies where the ring's rays meet it";
}

}  // namespace
}  // namespace cranioplan
