#include "cranioplan/model/marker.h"

namespace cranioplan {

std::optional<Eigen::Vector3d> edge_marker_centre(const std::vector<Marker>& markers) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  int edges = 0;
  for (const auto& m : markers)
    if (is_edge(m.type)) {
      sum += m.position;
      ++edges;
    }
  if (edges == 0) return std::nullopt;
  return Eigen::Vector3d(sum / edges);
}

const char* to_string(MarkerType t) {
  switch (t) {
    case MarkerType::OuterEdge:
      return "outer edge";
    case MarkerType::InnerEdge:
      return "inner edge";
    case MarkerType::OuterSurface:
      return "outer surface";
    case MarkerType::InnerSurface:
      return "inner surface";
  }
  return "unknown";
}

const char* to_string(MarkerSurface s) {
  return s == MarkerSurface::Original ? "original" : "mirrored";
}

}  // namespace cranioplan
