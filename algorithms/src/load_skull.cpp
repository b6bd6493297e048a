#include "cranioplan/algorithms/load_skull.h"

#include <chrono>
#include <cstdlib>

#include "cranioplan/algorithms/read_mesh.h"
#include "cranioplan/algorithms/read_volume.h"
#include "cranioplan/model/error.h"

namespace cranioplan {

std::string sample_case_path() {
  const char* env = std::getenv("CRANIOPLAN_SAMPLE");
  if (env && *env) return env;
  return "/usr/share/doc/invesalius-examples/examples/Cranium.inv3";
}

LoadedSkull load_skull(const std::string& path, const ExtractBoneSurfaceParams& import) {
  const auto t0 = std::chrono::steady_clock::now();
  LoadedSkull out;
  if (is_volume_path(path)) {
    const Volume volume = read_volume(path);
    out.surface = extract_bone_surface(volume, import);
    if (!out.surface.usable()) throw InputError(path, out.surface.message);
    // OpenMesh meshes cannot be moved (std::move copies), so the import's copy is cleared.
    out.mesh = out.surface.mesh;
    out.surface.mesh.clear();
    out.source_kind = "volume";
    out.description = volume.description;
  } else {
    ReadMeshParams read;
    read.canonical = import.canonical;
    MeshFile file = read_mesh(path, read);
    out.mesh = file.mesh;  // a copy (OpenMesh meshes cannot be moved); `file` goes at once
    out.source_kind = "mesh";
    out.description = file.format;
    out.warnings = std::move(file.warnings);
  }
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return out;
}

}  // namespace cranioplan
