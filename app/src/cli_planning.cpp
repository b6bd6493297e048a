#include "cli_planning.h"

#include <CLI/CLI.hpp>

#include "cranioplan/algorithms/io/load_skull.h"

namespace cranioplan::cli {

// Meshes, or label volumes (e.g. SkullFix NRRD masks) turned into surfaces with every piece kept.
SkullMesh load_any(const std::string& path) {
  ExtractBoneSurfaceParams p;
  p.largest_piece_only = false;
  p.min_piece_triangles = 1;
  return load_surface(path, p).mesh;
}

// --fit-to-bone MM: the automatic planner's implant built beyond the rim and trimmed by the bone.
void add_fit_option(CLI::App* cmd, AutoplanParams& params) {
  cmd->add_option("--fit-to-bone", params.implant.fit_to_bone_mm,
                  "build the implant this far over the bone and subtract the skull (mm; 0: off)")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 10.0));
  cmd->add_option("--local-registration", params.local_registration_mm,
                  "register the mirror again within this margin of the opening (mm; 0: off)")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 200.0));
}

}  // namespace cranioplan::cli
