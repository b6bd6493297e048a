#include "cranioplan/algorithms/io/load_skull.h"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>

#include "cranioplan/algorithms/geometry/voxelize_mesh.h"
#include "cranioplan/algorithms/io/mesh_report.h"
#include "cranioplan/algorithms/io/read_mesh.h"
#include "cranioplan/algorithms/io/read_volume.h"
#include "cranioplan/model/error.h"

namespace cranioplan {

const char* to_string(SkullSource source) {
  return source == SkullSource::Volume ? "volume" : "mesh";
}

std::string sample_case_path() {
  const char* env = std::getenv("CRANIOPLAN_SAMPLE");
  if (env && *env) return env;
  return "/usr/share/doc/invesalius-examples/examples/Cranium.inv3";
}

SoupRepairParams skull_repairs(const ExtractBoneSurfaceParams& import) {
  SoupRepairParams p;
  p.drop_repeated = import.drop_repeated_triangles;
  p.orient = import.orient_consistently;
  p.close_holes_mm = import.close_holes_mm;
  p.through_corners = import.close_holes_through_corners;
  return p;
}

namespace {

// A skull (`as_skull`: turned outward when the file winds it inward) or any surface.
LoadedSkull load(const std::string& path, const ExtractBoneSurfaceParams& import, bool as_skull) {
  const auto t0 = std::chrono::steady_clock::now();
  LoadedSkull out;
  if (is_volume_path(path)) {
    ReadVolumeParams read;
    read.dicom_series = import.dicom_series;
    read.patient_frame = import.patient_frame;
    const Volume volume = read_volume(path, read);
    // Built in place: OpenMesh meshes cannot be moved (assigning one copies it).
    out.surface = extract_bone_surface(volume, import, out.mesh);
    if (!out.surface.usable()) throw InputError(path, out.surface.message);
    out.source_kind = SkullSource::Volume;
    out.description = volume.description;
    out.frame = volume.frame;
    out.warnings = volume.warnings;
  } else {
    ReadMeshParams read;
    read.canonical = import.canonical;
    read.unit_mm = import.mesh_unit_mm;
    read.orient_outward = as_skull && import.orient_outward;
    if (as_skull) read.repairs = skull_repairs(import);
    read.far_piece_mm = as_skull && import.drop_far_pieces ? kFarPieceMm : 0.0;
    read.space_from_header = import.mesh_space_from_header;
    MeshSpace declared = MeshSpace::Undeclared;
    {
      // Built in place: OpenMesh meshes cannot be moved (assigning one copies it).
      MeshFile file = read_mesh(path, read, out.mesh);
      out.description = file.format;
      out.warnings = std::move(file.warnings);
      out.pieces_dropped = file.pieces_dropped;
      declared = out.declared_space = file.space;
      if (file.turned_to_lps) out.file_space = MeshSpace::RAS;
    }
    out.source_kind = SkullSource::Mesh;
    if (import.mesh_unit_mm != 1.0) {
      char unit[48];
      std::snprintf(unit, sizeof(unit), "units of %g mm", import.mesh_unit_mm);
      std::string named = unit;
      for (const LengthUnit& u : length_units())
        if (u.mm == import.mesh_unit_mm) named = u.label;
      out.description += " in " + named;
    }
    // Where a skull's surface is open, and what planning does about it.
    if (as_skull) {
      const MeshReport& report = out.report.emplace(report_mesh(out.mesh));
      for (const std::string& s : describe_openings(report))
        out.warnings.push_back(path + ": " + s);
      for (const std::string& s : describe_caps(report)) out.notes.push_back(path + ": " + s);
    }
    if (out.file_space == MeshSpace::RAS) {
      out.frame =
          "RAS, as the file declares (SPACE=RAS, as 3D Slicer writes it): read in the "
          "patient's LPS frame (x and y negated); exports are written back in RAS";
      out.notes.push_back(path +
                          ": declares its coordinates RAS (SPACE=RAS, as 3D Slicer writes "
                          "them); read in the patient's LPS frame, x and y negated, and "
                          "exports of the plan are written back in RAS, saying SPACE=RAS");
    } else if (declared == MeshSpace::RAS) {
      out.frame =
          "the file's own coordinates, taken as LPS (the file declares RAS, SPACE=RAS: "
          "read as it was before such declarations were read)";
    } else if (declared == MeshSpace::LPS) {
      out.frame = "LPS, as the file declares (SPACE=LPS, as 3D Slicer writes it)";
    } else {
      out.frame = "the file's own coordinates (a mesh file declares no frame), taken as LPS";
    }
  }
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return out;
}

}  // namespace

LoadedSkull load_surface(const std::string& path, const ExtractBoneSurfaceParams& import) {
  return load(path, import, false);
}

LoadedSkull load_skull(const std::string& path, const ExtractBoneSurfaceParams& import) {
  LoadedSkull out = load(path, import, true);
  check_skull_size(out.mesh, path,
                   out.source_kind == SkullSource::Mesh ? import.mesh_unit_mm : 0.0);
  return out;
}

const std::vector<LengthUnit>& length_units() {
  static const std::vector<LengthUnit> kUnits = {{"mm", "millimetres", 1.0},
                                                 {"cm", "centimetres", 10.0},
                                                 {"m", "metres", 1000.0},
                                                 {"in", "inches", 25.4},
                                                 {"um", "micrometres", 0.001}};
  return kUnits;
}

std::optional<LengthUnit> length_unit_named(const std::string& name) {
  for (const LengthUnit& u : length_units())
    if (name == u.name) return u;
  return std::nullopt;
}

void check_skull_size(const SkullMesh& mesh, const std::string& path, double read_unit_mm) {
  if (mesh.n_vertices() == 0) return;
  const auto [lo, hi] = mesh_bounds(mesh);
  const double extent = (hi - lo).maxCoeff();
  if (extent >= kSkullMinExtentMm && extent <= kSkullMaxExtentMm) return;
  auto mm = [](double v) {
    char buf[48];
    std::snprintf(buf, sizeof(buf), v < 10.0 ? "%.3g mm" : "%.0f mm", v);
    return std::string(buf);
  };
  std::string problem = "the surface is " + mm(extent) + " across at its largest, but a skull is " +
                        mm(kSkullMinExtentMm) + " to " + mm(kSkullMaxExtentMm) + " across";
  if (read_unit_mm <= 0.0)
    throw InputError(path, problem + ": check the voxel spacing in the volume's header");
  // The unit that makes it nearest the size of a head, if any.
  constexpr double kHeadMm = 190.0;  // an adult skull's largest extent, about
  const double in_file_units = extent / read_unit_mm;
  std::optional<LengthUnit> likely;
  for (const LengthUnit& u : length_units()) {
    const double size = in_file_units * u.mm;
    if (u.mm == read_unit_mm || size < kSkullMinExtentMm || size > kSkullMaxExtentMm) continue;
    if (!likely || std::abs(std::log(size / kHeadMm)) <
                       std::abs(std::log(in_file_units * likely->mm / kHeadMm)))
      likely = u;
  }
  if (!likely)
    throw InputError(path, problem + ": it is no skull, or not in a length unit Cranioplan reads");
  throw InputError(path, problem + ": the file looks to be in " + likely->label + " (then " +
                             mm(in_file_units * likely->mm) + " across); read it in " +
                             likely->label + " (length unit '" + likely->name + "')");
}

}  // namespace cranioplan
