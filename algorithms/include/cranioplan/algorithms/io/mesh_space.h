#pragma once
// The coordinate system a mesh file declares. Mesh formats carry none of their own; 3D Slicer
// writes one into the header ("SPACE=RAS" or "SPACE=LPS": an STL's 80-byte header or the text
// after "solid", a legacy VTK file's header line, a PLY's or OBJ's comment, a VTP's field data
// "SPACE"), and reads a file
// without it as LPS. Slicer wrote RAS until 2020 and still does when asked: such a skull,
// taken as LPS, has the patient's left and right, front and back swapped (a turn of 180° about
// the head's long axis; not a mirror image), and an implant written back without saying so
// lands on the other side of the head in Slicer.
#include <string_view>

namespace cranioplan {

enum class MeshSpace {
  Undeclared,  ///< no declaration: taken as LPS
  LPS,         ///< "SPACE=LPS": x to the patient's left, y posterior, z superior
  RAS,         ///< "SPACE=RAS": x to the patient's right, y anterior, z superior
};

/// The space declared in a header's or a comment's text, as 3D Slicer reads it: RAS where
/// "SPACE=RAS" appears, otherwise LPS where "SPACE=LPS" does.
inline MeshSpace space_in_text(std::string_view text) {
  if (text.find("SPACE=RAS") != std::string_view::npos) return MeshSpace::RAS;
  if (text.find("SPACE=LPS") != std::string_view::npos) return MeshSpace::LPS;
  return MeshSpace::Undeclared;
}

/// "SPACE=RAS" / "SPACE=LPS" / "" (undeclared).
inline const char* space_tag(MeshSpace space) {
  switch (space) {
    case MeshSpace::RAS:
      return "SPACE=RAS";
    case MeshSpace::LPS:
      return "SPACE=LPS";
    case MeshSpace::Undeclared:
      break;
  }
  return "";
}

/// Whether coordinates in `space` differ from the patient's LPS (x and y negated: the same
/// change both ways).
inline bool negates_x_and_y(MeshSpace space) { return space == MeshSpace::RAS; }

}  // namespace cranioplan
