#pragma once
// From a CT or label volume to a bone surface mesh.
#include <limits>
#include <string>
#include <vector>

#include "cranioplan/model/mesh.h"
#include "cranioplan/model/volume.h"

namespace cranioplan {

struct ExtractBoneSurfaceParams {
  /// Iso-value: Hounsfield units for CT (bone from about 200–400 HU), probability for masks.
  /// NaN means the volume kind's default (300 HU for CT, 0.5 for masks).
  double threshold = std::numeric_limits<double>::quiet_NaN();
  /// Keep only the largest connected piece (true), or every piece of at least
  /// `min_piece_triangles` triangles (false).
  bool largest_piece_only = true;
  long long min_piece_triangles = 1000;  ///< used when largest_piece_only is false; ≥ 1
  /// Decimate to about this many triangles (quadric decimation); 0 keeps full resolution.
  long long target_triangles = 0;
  /// The surface in canonical form (make_canonical), as every mesh read is, so that the same
  /// triangles from any file give the same plan; false: as the import (or, through load_skull,
  /// the file) gives it, as plans whose load_skull is version 1 were made.
  bool canonical = true;
  /// Through load_skull, a mesh file's length unit in millimetres (STL, PLY, OBJ and OFF carry
  /// none): 1 for mm, 10 for cm, 1000 for metres, 25.4 for inches. Volumes carry their spacing.
  double mesh_unit_mm = 1.0;
  /// Through load_skull, a mesh whose triangles wind inward is turned outward (with a warning);
  /// false: as the file gives it, as plans whose load_skull is version 1 or 2 read it. CT
  /// surfaces are
  /// made outward.
  bool orient_outward = true;
  /// Through load_skull, a mesh's patches that wind against their neighbours are turned to
  /// agree (ReadMeshParams::orient_consistently, with a warning); false: as the file gives it,
  /// as plans whose load_skull is version 1 to 4 read it.
  bool orient_consistently = true;
  /// Through load_skull, a mesh's triangles that repeat another's three corners are dropped
  /// (ReadMeshParams::drop_repeated_triangles, with a warning); false: every triangle kept, as
  /// plans whose load_skull is version 1 to 4 read it.
  bool drop_repeated_triangles = true;
  /// Through load_skull, a mesh's holes whose open edge is at most this long (mm) are closed
  /// (ReadMeshParams::close_holes_mm, with a warning): a skull's surface has no open edge of
  /// its own, and a hole a smoothing or a decimation left misleads every line through it about
  /// the bone's inside. The scan's end, a crop and a torn surface are longer. 0: left open, as
  /// plans whose load_skull is version 1 to 4 read it.
  double close_holes_mm = 15.0;
  /// With close_holes_mm, two holes that touch at a corner (two lost triangles sharing a
  /// vertex) are told apart and each closed (close_small_holes); false: both left open, as
  /// plans whose load_skull is version 1 to 5 read them.
  bool close_holes_through_corners = true;
  /// Through load_skull and load_surface, a mesh file that declares its coordinates RAS
  /// ("SPACE=RAS", as 3D Slicer writes it; mesh_space.h) is read in the patient's LPS frame, x
  /// and y negated, and what is planned on it is exported back in RAS; false: the file's
  /// coordinates taken as LPS, as plans whose load_skull is version 1 to 5 read them.
  bool mesh_space_from_header = true;
  /// Through load_skull, a volume's positions in the patient's LPS frame, whatever space the
  /// file declares (ReadVolumeParams::patient_frame); false: a NRRD's or NIfTI's positions as
  /// the file writes them, as plans saved before version 0.2 read them.
  bool patient_frame = true;
  /// Through load_skull, the series of a DICOM folder to read (SeriesInstanceUID); empty: the
  /// largest CT series.
  std::string dicom_series;
  /// Through load_skull, a skull mesh's pieces that lie apart from its largest piece (their
  /// bounding boxes more than `far_piece_mm` from its own) are dropped before the skull's size
  /// is checked, and reported: the CT table, a clip, noise. false: every piece kept, as plans
  /// saved before version 0.2 read them.
  bool drop_far_pieces = true;
};

/// How far a skull mesh's piece may lie from the largest piece's bounding box and be kept, mm
/// (the mandible, loose fragments in the defect, a separate orbit floor lie within).
constexpr double kFarPieceMm = 20.0;

struct ExtractBoneSurfaceResult {
  enum class Status { Ok, NoSurface };
  Status status = Status::Ok;
  std::string message;  ///< why there is no surface, e.g. threshold above every sample
  SkullMesh mesh;       ///< closed, outward-oriented, in the volume's world coordinates (mm)
  double threshold_used = 0.0;
  long long pieces_found = 0;
  long long pieces_kept = 0;
  long long triangles_before_decimation = 0;
  double seconds = 0.0;
  bool usable() const { return status == Status::Ok; }
};

ExtractBoneSurfaceResult extract_bone_surface(const Volume& volume,
                                              const ExtractBoneSurfaceParams& params = {});
/// The same, the surface built in `mesh` and the result's own mesh left empty (OpenMesh meshes
/// cannot be moved: assigning one copies it).
ExtractBoneSurfaceResult extract_bone_surface(const Volume& volume,
                                              const ExtractBoneSurfaceParams& params,
                                              SkullMesh& mesh);

struct VoxelGrid;
/// A solid given as a field on a grid (0 outside, 1 inside, ½ on its surface) meshed at ½: its
/// largest piece, in the order the meshing gives (not canonical: an implant fitted to the bone
/// or drilled follows from the canonical skull and the markers already).
ExtractBoneSurfaceResult surface_of_field(std::vector<float> field, const VoxelGrid& grid);
/// The same, the surface built in `mesh` (the result's own mesh left empty).
ExtractBoneSurfaceResult surface_of_field(std::vector<float> field, const VoxelGrid& grid,
                                          SkullMesh& mesh);
/// Moves the values of a 0..1 field within 1e-3 of ½ that far off it, on their side: a value at
/// or next to the iso-level puts a vertex on or next to a grid point, where the vertices of the
/// edges meeting there fall together into triangles without area, whose neighbours then seem
/// to cross. The surface moves by at most a thousandth of a voxel.
void keep_off_iso_level(std::vector<float>& field);
/// A solid given by its signed distance (mm, positive inside) meshed at 0: the field is mapped
/// to surface_of_field's 0..1 over one voxel on either side of the surface. Values within 1e-3
/// of ½ are moved that far off it, so that no vertices fall together into sliver triangles;
/// `iso_gap` false: only a value exactly at ½ (as plans saved before were meshed).
ExtractBoneSurfaceResult surface_of_signed_distance(std::vector<float> distance,
                                                    const VoxelGrid& grid, bool iso_gap = true);
/// The same, the surface built in `mesh` (the result's own mesh left empty).
ExtractBoneSurfaceResult surface_of_signed_distance(std::vector<float> distance,
                                                    const VoxelGrid& grid, SkullMesh& mesh,
                                                    bool iso_gap = true);

}  // namespace cranioplan
