#pragma once
// Dense correspondence between skulls for a shape model (shape_model.h).
//
// The template: two sheets over one skull's vault, one vertex per direction of a subdivided
// icosahedron seen from the vault's centre where a ray crosses exactly one layer of bone (its
// inner and outer table, faced square on); enclosed gaps (foramina, thin spots) are filled from
// their surroundings and the border is pulled in from the scan's cut.
//
// Each skull is reached by non-rigid ICP: a similarity found from 120 starting rotations (any
// pose), then a displacement field over each sheet that is the Gaussian-weighted average of the
// closest-point displacements both ways (template → skull and skull → template, pairs whose
// normals disagree dropped so that the outer sheet never takes the inner table), coarse to fine
// (widths 40, 20, 10, 5 mm). The smoothing is defined on the template's rest shape, so
// neighbouring vertices move alike at every scale (a coherent motion, as in coherent point drift
// and Gaussian-process morphable-model registration), and the finest width leaves the vertices
// within a fraction of a millimetre of the bone.
#include <Eigen/Core>
#include <functional>
#include <string>
#include <vector>

#include "cranioplan/model/mesh.h"

namespace cranioplan {

class SurfaceLocator;

/// A subdivided icosahedron: unit vertices and counter-clockwise (outward) faces; 10·4^k + 2
/// vertices after k subdivisions.
struct Icosphere {
  std::vector<Eigen::Vector3d> vertices;
  std::vector<Eigen::Vector3i> faces;
};
Icosphere icosphere(int subdivisions);

struct ShapeTemplate {
  int outer_count = 0;                               ///< vertices [0, outer_count): outer sheet
  std::vector<Eigen::Vector3i> triangles;            ///< outward from the bone
  Eigen::Matrix3Xd points;                           ///< outer sheet, then inner sheet
  Eigen::Vector3d center = Eigen::Vector3d::Zero();  ///< the vault's centre the rays left
};

struct ShapeTemplateParams {
  int subdivisions = 5;            ///< of the icosahedron (5: 10,242 directions, ~2°), 2..6
  double min_thickness_mm = 1.0;   ///< a ray's bone thinner than this is no vault
  double max_thickness_mm = 15.0;  ///< thicker than this: a fossa, a sinus, the skull base
  double max_tilt_deg = 60.0;      ///< tables tilted more than this from the ray are a cut face
  int border_rings = 3;            ///< rings of directions dropped along the border (the cut)
};

/// The template from one complete skull. Throws nothing; an empty template (no vault found) has
/// no points.
ShapeTemplate make_shape_template(const SkullMesh& skull, const ShapeTemplateParams& params = {});

/// Every k-th vertex of `mesh`, at most about `count` of them (k = vertices / count, at least
/// 1): for sphere fits, the pose search and the reverse pairing.
std::vector<Eigen::Vector3d> vertex_sample(const SkullMesh& mesh, size_t count);

/// A similarity (scale, rotation, translation) as a 4×4 matrix.
using Similarity = Eigen::Matrix4d;

struct AlignParams {
  int samples = 3000;             ///< template points used
  int iterations = 40;            ///< of the final ICP
  double max_distance_mm = 15.0;  ///< pairs further apart are not used
  double max_normal_angle_deg = 60.0;
  bool with_scale = true;
};
struct AlignResult {
  Similarity transform = Similarity::Identity();
  double rms_mm = 0.0;  ///< over the pairs used
  double used = 0.0;    ///< share of the points paired
};
/// Moves `points` (with unit `normals`) onto the surface `target`: from 120 rotations about the
/// centres of spheres fitted to each (or from `start` alone when given), trimmed similarity ICP.
/// `usable(i)`, when given, says which points may pair (the rest are left out).
AlignResult align_to_surface(const Eigen::Matrix3Xd& points, const Eigen::Matrix3Xd& normals,
                             const SurfaceLocator& target,
                             const std::vector<Eigen::Vector3d>& target_points,
                             const AlignParams& params = {}, const Similarity* start = nullptr,
                             const std::function<bool(Eigen::Index)>& usable = nullptr);

/// Unit vertex normals of sheets made of `triangles` at `points` (area-weighted).
Eigen::Matrix3Xd sheet_normals(const std::vector<Eigen::Vector3i>& triangles,
                               const Eigen::Matrix3Xd& points);

/// Closest-point pairs of `points[which]` (moved by `T`) on `surface`: within `reach` mm and
/// where the surface's normal is within `max_normal_angle_deg` of the point's (moved) normal.
struct SurfacePairs {
  std::vector<Eigen::Index> index;
  std::vector<Eigen::Vector3d> target;
  std::vector<Eigen::Vector3d> normal;  ///< the surface's unit normal there
  std::vector<double> distance;
};
SurfacePairs pair_with_surface(const Eigen::Matrix3Xd& points, const Eigen::Matrix3Xd& normals,
                               const std::vector<Eigen::Index>& which, const Similarity& T,
                               const SurfaceLocator& surface, double reach,
                               double max_normal_angle_deg);

struct CorrespondParams {
  AlignParams align;
  std::vector<double> kernel_mm = {40.0, 20.0, 10.0, 5.0};  ///< coarse to fine
  int iterations = 8;                                       ///< per width
  double max_distance_mm = 10.0;                            ///< pairs further apart are not used
  double max_normal_angle_deg = 60.0;
};

struct Correspondence {
  enum class Status { Corresponded, Failed };
  Status status = Status::Failed;
  std::string message;
  Eigen::Matrix3Xd points;  ///< the template's vertices on the skull, in the skull's frame
  double rms_mm = 0.0;      ///< vertices within reach of the bone: distance to it, RMS
  double matched = 0.0;     ///< share of vertices within 2 mm of the bone
  bool ok() const { return status == Status::Corresponded; }
};

/// The template brought onto `skull` (non-rigid ICP, see above).
Correspondence correspond_skull(const ShapeTemplate& shape_template, const SkullMesh& skull,
                                const CorrespondParams& params = {});

}  // namespace cranioplan
