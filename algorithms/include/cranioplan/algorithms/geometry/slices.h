#pragma once
// Slices through the patient for the wizard's slice views: a volume sampled on an axial,
// coronal or sagittal plane of the patient's LPS frame (whatever the volume's own grid), and a
// mesh cut by the same plane. Display conventions are radiological, as in 3D Slicer: axial seen
// from the feet (the patient's right on the left, anterior up), coronal seen from the front
// (right on the left, superior up), sagittal seen from the patient's left (anterior on the
// left, superior up).
#include <Eigen/Core>
#include <array>
#include <vector>

#include "cranioplan/model/mesh.h"
#include "cranioplan/model/volume.h"

namespace cranioplan {

enum class SliceOrientation { Axial, Coronal, Sagittal };
const char* to_string(SliceOrientation o);

/// A slice's pixel grid in the patient frame: pixel (c, r) — column c to the right, row r down
/// — is at origin + c·right + r·down (mm); `normal` is the axis the slice is across.
struct SliceGeometry {
  SliceOrientation orientation = SliceOrientation::Axial;
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();
  Eigen::Vector3d right = Eigen::Vector3d::UnitX();   ///< one pixel to the right, mm
  Eigen::Vector3d down = Eigen::Vector3d::UnitY();    ///< one pixel down, mm
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();  ///< unit, along +z, +y or +x
  int width = 0, height = 0;
  double position_mm = 0.0;  ///< where the slice lies along `normal` (its coordinate), mm
  /// The letters at the left, right, top and bottom edges ("R", "L", "A", "P").
  std::array<const char*, 4> edge_labels{};

  Eigen::Vector3d world(double column, double row) const {
    return origin + column * right + row * down;
  }
  /// Where a point lies in the slice (column, row), and how far off its plane (mm, along normal).
  Eigen::Vector2d pixel(const Eigen::Vector3d& point) const;
  double distance(const Eigen::Vector3d& point) const { return normal.dot(point) - position_mm; }
};

/// The slice of `orientation` through `point`, covering the volume's extent in the patient
/// frame, with square pixels of the volume's smallest spacing (or `pixel_mm` when > 0).
SliceGeometry slice_through(const Volume& volume, SliceOrientation orientation,
                            const Eigen::Vector3d& point, double pixel_mm = 0.0);

/// The volume at a patient point (trilinear); NaN outside it.
double sample_volume(const Volume& volume, const Eigen::Vector3d& point);

/// The volume sampled at each pixel of the slice (trilinear), row by row; NaN outside it.
std::vector<float> sample_slice(const Volume& volume, const SliceGeometry& slice);

/// A segment of a mesh's cut, in the patient frame.
using CutSegment = std::array<Eigen::Vector3d, 2>;
/// The segments where the plane n·x = d (n unit) cuts the mesh's triangles: a closed surface
/// gives closed polygons.
std::vector<CutSegment> cut_mesh(const SkullMesh& mesh, const Eigen::Vector3d& normal, double d);

/// Grey levels 0..255 of `values` shown with window `window` centred on `level` (same units as
/// the values); NaN (outside the volume) shows black.
std::vector<uint8_t> window_level(const std::vector<float>& values, double window, double level);

}  // namespace cranioplan
