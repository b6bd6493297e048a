#pragma once
// Shapes whose truth is known by construction, for known-answer tests.
#include <gtest/gtest.h>

#include "cranioplan/algorithms/planning/detect_defect.h"
#include "cranioplan/model/landmarks.h"
#include "cranioplan/model/marker.h"
#include "cranioplan/model/mesh.h"
#include "cranioplan/model/plane.h"
#include "cranioplan/model/rigid_transform.h"
#include "cranioplan/model/volume.h"

namespace cranioplan {
struct ShapeModel;
}

namespace cranioplan::test {

/// A small shape model of `head` stretched three ways (as it is; 3 %, 2 % and 2 % along the
/// axes), its template on `head` (4 subdivisions): a model whose mean is the head itself, for
/// tests of how plans use a model rather than of its accuracy.
ShapeModel stretched_head_model(const SkullMesh& head);

/// A closed, outward-oriented head-like surface, mirror-symmetric across x = 0 exactly (the
/// vertex set is symmetric), about 140 × 180 × 150 mm, with a nose ridge at +y and a flattened
/// back, so no other plane is a symmetry plane. `subdivisions` 4 gives 5,120 triangles,
/// 5 gives 20,480.
SkullMesh make_symmetric_head(int subdivisions = 5);

/// Landmarks of make_symmetric_head(): nasion on the midline, orbit centres mirrored.
Landmarks head_landmarks();

/// A closed, outward-oriented axis-aligned box as a triangle soup (12 triangles).
TriangleSoup box_soup(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi);

/// The box [lo, hi] meshed from its voxel mask on a 0.5 mm grid reaching 2.25 mm beyond it, as
/// implants are meshed (each face halfway between voxel centres, the corners cut).
SkullMesh mask_meshed_box(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi);
/// The union of boxes, each given as {lo, hi}, meshed the same way.
SkullMesh mask_meshed_boxes(const std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>>& boxes);

/// The genus of a closed surface from its Euler characteristic V − E + F = 2 − 2·genus: one per
/// tunnel through it (a drilled hole, a screw hole).
long long genus(const SkullMesh& mesh);

/// Removes every face whose centroid lies within `radius` of `center`.
SkullMesh cut_hole(const SkullMesh& mesh, const Eigen::Vector3d& center, double radius);

/// Keeps the faces whose three vertices lie on or above the plane through `point` with normal
/// `up`: the surface marching cubes gives when the scan ends at that plane (open there, as most
/// exporters leave it).
SkullMesh cut_open(const SkullMesh& mesh, const Eigen::Vector3d& point, const Eigen::Vector3d& up);

/// The closed `mesh` as an importer that pads the volume meshes a scan that ended at the plane
/// through `point` with normal `up`: voxelized on `voxel_mm` voxels, those below the plane
/// cleared, the iso-surface closed by the padding (a flat cap across the bone where an axis
/// plane cuts it). Every piece is kept.
SkullMesh scanned_padded(const SkullMesh& mesh, const Eigen::Vector3d& point,
                         const Eigen::Vector3d& up, double voxel_mm = 1.0);

SkullMesh transformed(const SkullMesh& mesh, const RigidTransform& t);
/// The mesh with every coordinate multiplied by `factor` (a head written in another unit:
/// 1/1000 for metres).
SkullMesh scaled(const SkullMesh& mesh, double factor);
Landmarks transformed(const Landmarks& lm, const RigidTransform& t);
Plane transformed(const Plane& p, const RigidTransform& t);

/// A volume holding a solid ball (values 1 inside, 0 outside; or HU 1000 / -1000 as CT).
Volume make_ball_volume(const Eigen::Vector3d& center_world, double radius, int n, double spacing,
                        bool as_ct);
/// A mask of a ball of radius 10 mm centred on `center`, on an oblique 32³ grid (turned and
/// sheared, spacings 0.9, 1.0 and 1.3 mm): a reader must put it where the directions say.
Volume oblique_ball_volume(const Eigen::Vector3d& center);
/// A head whose truth is known: the intact thick head, and the same with a 55 mm defect on the
/// upper right, detected from the origin (inside the cranial cavity). Made once.
struct ThickHeadDefect {
  SkullMesh intact, defective;
  DefectRegion defect;
};
const ThickHeadDefect& thick_head_defect();

}  // namespace cranioplan::test

namespace cranioplan::test {

/// Point of the head surface of make_symmetric_head() along unit direction u (exact surface).
Eigen::Vector3d head_surface_point(const Eigen::Vector3d& u);

/// A closed skull-like shell: the volume between the head surface and the same surface scaled
/// by `inner_scale`, meshed from a voxel mask of `voxel_mm`. Symmetric across x = 0 up to the
/// voxelisation.
SkullMesh make_thick_head(double inner_scale = 0.93, double voxel_mm = 0.5);

/// Markers of a round defect cut by a sphere (centre `center`, radius `radius`) out of
/// make_thick_head(): `edge_count` outer and inner edge markers on the rim, and surface markers
/// on rings inside taken from the intact surfaces (what a mirrored healthy side supplies).
std::vector<Marker> round_defect_markers(const Eigen::Vector3d& center, double radius,
                                         double inner_scale = 0.93, int edge_count = 16,
                                         int surface_rings = 3);

/// The sample case's defect, where it is in the patient: on the right (−x in LPS, the side of
/// `plane` away from +x) and in front (−y). A reader or a plan that mirrored the skull fails.
::testing::AssertionResult on_the_patients_right_in_front(const Plane& plane,
                                                          const DefectRegion& defect);

}  // namespace cranioplan::test
