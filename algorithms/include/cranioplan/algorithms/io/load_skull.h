#pragma once
// One entry point for a skull from any supported file: a surface mesh, or a CT / label volume
// turned into a bone surface.
#include <optional>
#include <string>
#include <vector>

#include "cranioplan/algorithms/geometry/mesh_components.h"
#include "cranioplan/algorithms/io/extract_bone_surface.h"
#include "cranioplan/algorithms/io/mesh_report.h"
#include "cranioplan/algorithms/io/mesh_space.h"
#include "cranioplan/model/mesh.h"

namespace cranioplan {

/// The sample case installed by Debian's invesalius-examples (override with the environment
/// variable CRANIOPLAN_SAMPLE).
std::string sample_case_path();

/// What a skull was read from: a surface mesh, or a volume (CT or mask) made into its bone.
enum class SkullSource { Mesh, Volume };
/// "mesh" or "volume", as `inspect --json` says it.
const char* to_string(SkullSource source);

struct LoadedSkull {
  SkullMesh mesh;
  SkullSource source_kind = SkullSource::Mesh;
  std::string description;            ///< format / volume description
  std::vector<std::string> warnings;  ///< reader warnings, each naming the file
  /// What a skull mesh has that needs no repair (a flat cap where the scan ended), each naming
  /// the file: not among the warnings, which a plan records as its input's repair report.
  std::vector<std::string> notes;
  /// The frame the file declared and how it was brought to the patient's LPS (Volume::frame).
  std::string frame;
  /// The coordinates a mesh file gave, when they were not the patient's LPS: RAS for a file
  /// that declares so (mesh_space.h), read in LPS; exports of what is planned on it are written
  /// back in RAS (encode_mesh's `space`). Undeclared otherwise (a volume: LPS).
  MeshSpace file_space = MeshSpace::Undeclared;
  /// The coordinate system a mesh file declares (mesh_space.h), whether or not it was read so.
  MeshSpace declared_space = MeshSpace::Undeclared;
  long long pieces_dropped = 0;  ///< a mesh's pieces far from the skull (drop_far_pieces)
  /// A skull mesh's report as read (report_mesh: where it is open, its caps), which planning
  /// can take its scan's borders from (scan_borders) instead of finding them again; none for a
  /// volume, or a surface not read as a skull.
  std::optional<MeshReport> report;
  ExtractBoneSurfaceResult
      surface;  ///< details of the CT import (volumes only; its mesh is cleared)
  double seconds = 0.0;
};

/// Reads a mesh (in `import.mesh_unit_mm`), or imports a volume with `import` parameters: any
/// surface, e.g. an implant. Throws InputError for bad files, including a volume in which the
/// threshold finds no surface.
LoadedSkull load_surface(const std::string& path, const ExtractBoneSurfaceParams& import = {});

/// load_surface, for a skull to plan on: a mesh that winds inward is turned outward (with a
/// warning; `import.orient_outward`), and a surface that cannot be a skull in millimetres by
/// its size is an InputError as well (check_skull_size).
LoadedSkull load_skull(const std::string& path, const ExtractBoneSurfaceParams& import = {});

/// The repairs load_skull makes to a skull mesh's soup (ReadMeshParams::repairs), as `import`
/// asks for them; `info` reports what they would do to a file.
SoupRepairParams skull_repairs(const ExtractBoneSurfaceParams& import);

/// A length unit a mesh file may be written in.
struct LengthUnit {
  const char* name;   ///< as the command line takes it: "mm", "cm", "m", "in", "um"
  const char* label;  ///< for people: "millimetres", ...
  double mm;          ///< millimetres per unit
};
const std::vector<LengthUnit>& length_units();
/// The unit called `name` (LengthUnit::name), or none.
std::optional<LengthUnit> length_unit_named(const std::string& name);

/// The largest side of a skull's bounding box, mm: from a child's vault cropped close to an
/// adult's head with its neck and jaw. Planning's distances (bone thickness, ring widths, marker
/// spacing) are millimetres; a surface outside these sizes is in another unit, or no skull.
constexpr double kSkullMinExtentMm = 60.0, kSkullMaxExtentMm = 500.0;

/// Throws InputError naming `path` when `mesh`'s largest extent lies outside the skull's range,
/// saying which unit the file looks to be in (the one that would make it the size of a head) and
/// how to read it so. `read_unit_mm`: the unit the file was read in (a volume's own: 0).
void check_skull_size(const SkullMesh& mesh, const std::string& path, double read_unit_mm);

}  // namespace cranioplan
