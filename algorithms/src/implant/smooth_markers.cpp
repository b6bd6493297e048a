#include "cranioplan/algorithms/implant/smooth_markers.h"

#include <algorithm>
#include <cassert>

#include "cranioplan/algorithms/geometry/surface_locator.h"

namespace cranioplan {
namespace {
constexpr double kCoincident2 = 1e-18;  // (1 nm)², in mm²
}  // namespace

std::string smooth_problem(const SmoothParams& p) { return range_problems("the smoothing's", p); }

SmoothResult smooth_markers(const std::vector<Marker>& markers, const SmoothParams& params,
                            const SurfaceLocator* project_onto) {
  assert(smooth_problem(params).empty());
  SmoothResult result;
  result.markers = markers;
  if (markers.size() < 3) {
    result.status = SmoothResult::Status::TooFewMarkers;
    result.message = "smoothing needs at least 3 markers (" + std::to_string(markers.size()) +
                     " given); nothing was changed";
    return result;
  }
  const double r2 = params.radius_mm * params.radius_mm;
  std::vector<Eigen::Vector3d> current(markers.size());
  for (size_t i = 0; i < markers.size(); ++i) current[i] = markers[i].position;
  for (int it = 0; it < params.iterations; ++it) {
    std::vector<Eigen::Vector3d> next = current;
    for (size_t i = 0; i < markers.size(); ++i) {
      if (is_edge(markers[i].type)) continue;
      const bool outer = is_outer(markers[i].type);
      Eigen::Vector3d sum = current[i];
      double weight = 1.0;
      for (size_t j = 0; j < markers.size(); ++j) {
        if (j == i || is_outer(markers[j].type) != outer) continue;
        const double d2 = (current[j] - current[i]).squaredNorm();
        // 0 < dist <= radius. Markers closer than 1 nm count as coincident: two markers that
        // smoothing moves onto the same place must not be in or out by a rounding error, or
        // the result would depend on the order of the markers.
        if (d2 <= kCoincident2 || d2 > r2) continue;
        const double w = is_edge(markers[j].type) ? params.edge_weight : 1.0;
        sum += w * current[j];
        weight += w;
      }
      next[i] = sum / weight;
      if (project_onto) next[i] = project_onto->closest(next[i]).point;
    }
    current = std::move(next);
  }
  for (size_t i = 0; i < markers.size(); ++i) {
    result.max_move_mm = std::max(result.max_move_mm, (current[i] - markers[i].position).norm());
    result.markers[i].position = current[i];
  }
  result.message = "smoothed " + std::to_string(params.iterations) + " iteration(s)";
  return result;
}

}  // namespace cranioplan
