#include "cranioplan/algorithms/implant/snap_markers.h"

#include <algorithm>
#include <cstdio>

#include "cranioplan/algorithms/geometry/surface_locator.h"

namespace cranioplan {

SnapMarkersResult snap_markers(const std::vector<Marker>& markers, const SurfaceLocator& original,
                               const SurfaceLocator* mirrored, const SnapMarkersParams& params) {
  SnapMarkersResult result;
  result.markers = markers;
  std::vector<Marker> snapped = markers;
  for (auto& m : snapped) {
    const SurfaceLocator& surface =
        m.surface == MarkerSurface::Mirrored && mirrored ? *mirrored : original;
    const auto c = surface.closest(m.position);
    if (c.distance > params.max_distance_mm) {
      char buf[200];
      std::snprintf(buf, sizeof(buf), "marker %d (%s) is %.1f mm from the %s skull (limit %.1f mm)",
                    m.id, to_string(m.type), c.distance, to_string(m.surface),
                    params.max_distance_mm);
      result.status = SnapMarkersResult::Status::TooFar;
      result.message = buf;
      return result;
    }
    result.max_distance_mm = std::max(result.max_distance_mm, c.distance);
    m.position = c.point;
  }
  result.markers = std::move(snapped);
  result.message = "snapped " + std::to_string(markers.size()) + " markers";
  return result;
}

}  // namespace cranioplan
