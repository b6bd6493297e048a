#pragma once
#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

namespace cranioplan {

/// The paper's four marker types. Edge markers lie on the original skull along the defect rim;
/// surface markers lie on the mirrored skull inside the defect.
enum class MarkerType : int { OuterEdge = 0, InnerEdge = 1, OuterSurface = 2, InnerSurface = 3 };

/// Which surface a marker lies on.
enum class MarkerSurface : int { Original = 0, Mirrored = 1 };

struct Marker {
  int id = 0;  ///< stable id, unique within a plan, never reused
  MarkerType type = MarkerType::OuterEdge;
  Eigen::Vector3d position = Eigen::Vector3d::Zero();  ///< mm
  MarkerSurface surface = MarkerSurface::Original;
};

inline bool is_edge(MarkerType t) {
  return t == MarkerType::OuterEdge || t == MarkerType::InnerEdge;
}
inline bool is_outer(MarkerType t) {
  return t == MarkerType::OuterEdge || t == MarkerType::OuterSurface;
}
/// The surface a marker of this type belongs on (edge: original skull; surface: mirrored).
inline MarkerSurface default_surface(MarkerType t) {
  return is_edge(t) ? MarkerSurface::Original : MarkerSurface::Mirrored;
}
/// Centre of the edge markers (types 0 and 1); none when there are none.
std::optional<Eigen::Vector3d> edge_marker_centre(const std::vector<Marker>& markers);

const char* to_string(MarkerType t);
const char* to_string(MarkerSurface s);

}  // namespace cranioplan
