#pragma once
// 3MF packages (the 3D Manufacturing Format that slicers and print services take) through
// lib3mf: named parts in millimetres with the plan's metadata, written byte for byte the same
// for the same parts (so a plan's replay can check an export's SHA-256), and read back.
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "cranioplan/model/mesh.h"

namespace cranioplan {

/// A named part of a package (an implant, a mould half).
struct Part3mf {
  std::string name;
  const SkullMesh* mesh = nullptr;
};

/// The bytes of a 3MF package in millimetres: each part a mesh object of its name with a build
/// item, and `metadata` (3MF core names: "Title", "Designer", "Description", "Application",
/// ...; lib3mf reads no other name back without a namespace of its own). The objects' and build's
/// UUIDs are derived from the parts' contents. Throws InputError (path "3MF") when lib3mf refuses
/// the model.
std::string encode_3mf(const std::vector<Part3mf>& parts,
                       const std::vector<std::pair<std::string, std::string>>& metadata);

/// What a 3MF package holds: its parts (name and mesh, in millimetres) and its metadata.
struct Read3mf {
  std::vector<std::pair<std::string, SkullMesh>> parts;
  std::map<std::string, std::string> metadata;
  double unit_mm = 1.0;  ///< the file's length unit, in millimetres
};
/// Reads a 3MF package with lib3mf; throws InputError naming the file and lib3mf's complaint.
/// Parts in other units are scaled to millimetres.
Read3mf read_3mf(const std::string& path);

}  // namespace cranioplan
