#pragma once
// The paper's Laplacian marker smoother (Egger et al. 2017), with the evident intent of its
// printed distance test (0 < dist <= radius).
#include <string>
#include <vector>

#include "cranioplan/model/marker.h"
#include "cranioplan/model/mesh.h"
#include "cranioplan/model/param_spec.h"

namespace cranioplan {

class SurfaceLocator;

// The fields' ranges, units and meanings are declared in for_each_field below.
struct SmoothParams {
  double radius_mm = 10.0;   ///< neighbours within this distance take part
  double edge_weight = 2.0;  ///< an edge marker counts this many times
  int iterations = 1;        ///< each uses the previous iteration's positions
};

/// SmoothParams' fields, each declared once (ParamSpec), in the order a session writes them.
template <class Visit>
void for_each_field(Visit&& visit, SmoothParams& p) {
  visit(length_mm("radius_mm", "radius", 1, 100)
            .with_option("radius", "a surface marker moves towards the markers within this radius"),
        p.radius_mm);
  visit(number("edge_weight", "edge-marker weight", 1, 100)
            .with_option("edge-weight", "an edge marker counts this many times in the mean"),
        p.edge_weight);
  visit(number("iterations", "iterations", 1, 100)
            .with_option("iterations", "rounds, each from the previous round's positions"),
        p.iterations);
}

/// Why `p` cannot be used ("the smoothing's radius must be 1 to 100 mm (0.5 given)"), or empty.
std::string smooth_problem(const SmoothParams& p);

struct SmoothResult {
  enum class Status { Smoothed, TooFewMarkers };
  Status status = Status::Smoothed;
  std::string message;
  std::vector<Marker> markers;  ///< same order and ids as the input
  double max_move_mm = 0.0;     ///< largest displacement of a surface marker
};

/// Each surface marker (types 2, 3) moves to the weighted mean of itself and the markers of the
/// same layer (outer: 0 and 2; inner: 1 and 3) within `radius_mm`, edge markers counting
/// `edge_weight` times. Edge markers never move. With fewer than three markers nothing changes
/// and the status says why. When `project_onto` is given, moved surface markers are put back
/// onto that surface (the mirrored skull), since smoothing shrinks.
SmoothResult smooth_markers(const std::vector<Marker>& markers, const SmoothParams& params,
                            const SurfaceLocator* project_onto = nullptr);

}  // namespace cranioplan
