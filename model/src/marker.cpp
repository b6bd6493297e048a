#include "cranioplan/model/marker.h"

namespace cranioplan {

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
