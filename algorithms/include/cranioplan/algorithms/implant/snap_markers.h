#pragma once
#include <string>
#include <vector>

#include "cranioplan/model/marker.h"

namespace cranioplan {

class SurfaceLocator;

struct SnapMarkersParams {
  double max_distance_mm = 10.0;  ///< a marker farther than this from its surface is refused
};

struct SnapMarkersResult {
  enum class Status { Snapped, TooFar };
  Status status = Status::Snapped;
  std::string message;           ///< names the first marker too far away
  std::vector<Marker> markers;   ///< snapped (or the input, unchanged, when TooFar)
  double max_distance_mm = 0.0;  ///< largest snap distance
};

/// Moves every marker to the closest point of its surface (`original` for markers on the
/// original skull, `mirrored` for the others; a null mirrored surface means the original).
SnapMarkersResult snap_markers(const std::vector<Marker>& markers, const SurfaceLocator& original,
                               const SurfaceLocator* mirrored,
                               const SnapMarkersParams& params = {});

}  // namespace cranioplan
