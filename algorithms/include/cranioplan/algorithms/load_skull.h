#pragma once
// One entry point for a skull from any supported file: a surface mesh, or a CT / label volume
// turned into a bone surface.
#include <string>
#include <vector>

#include "cranioplan/algorithms/extract_bone_surface.h"
#include "cranioplan/model/mesh.h"

namespace cranioplan {

/// The sample case installed by Debian's invesalius-examples (override with the environment
/// variable CRANIOPLAN_SAMPLE).
std::string sample_case_path();

struct LoadedSkull {
  SkullMesh mesh;
  std::string source_kind;            ///< "mesh" or "volume"
  std::string description;            ///< format / volume description
  std::vector<std::string> warnings;  ///< reader warnings, each naming the file
  ExtractBoneSurfaceResult
      surface;  ///< details of the CT import (volumes only; its mesh is cleared)
  double seconds = 0.0;
};

/// Reads a mesh, or imports a volume with `import` parameters. Throws InputError for bad files,
/// including a volume in which the threshold finds no surface.
LoadedSkull load_skull(const std::string& path, const ExtractBoneSurfaceParams& import = {});

}  // namespace cranioplan
