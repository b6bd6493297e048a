#pragma once
// 3D Slicer's markups files (.mrk.json, markups schema 1.0.3): lists of control points.
//
// Written: markers as one "Fiducial" list per marker type, named after the type ("outer edge",
// "inner edge", "outer surface", "inner surface"); each point's id is the marker's id, its label
// "<type> <id>", its description the surface it lies on ("original" or "mirrored"). Landmarks as
// one list named "landmarks", its points labelled nasion, orbit_left, orbit_right, midline-N.
// Positions in millimetres in LPS, the plan's patient frame (docs/FILES.md).
//
// Read: every "Fiducial" list of the file. Positions in RAS are turned to LPS, micrometres to
// millimetres; points whose position is not defined are left out. A marker's type comes from
// its list's name or, failing that, its label; its surface from the description (else the
// type's own); its id from the point's id when that is a whole number not used before.
#include <string>
#include <vector>

#include "cranioplan/model/landmarks.h"
#include "cranioplan/model/marker.h"
#include "cranioplan/sessions/plan_files.h"

namespace cranioplan {

/// Whether the path names a markups file (ends in .mrk.json, any case).
bool is_markups_path(const std::string& path);

Json markers_to_markups(const std::vector<Marker>& markers);
/// Throws InputError naming `source` and the list or point at fault.
std::vector<Marker> markers_from_markups(const Json& j, const std::string& source);

Json landmarks_to_markups(const Landmarks& landmarks);
/// Points labelled nasion, orbit_left (or "left orbit"), orbit_right and midline...; other
/// labels are an error naming them; a file without points gives no landmarks. Throws
/// InputError.
Landmarks landmarks_from_markups(const Json& j, const std::string& source);

}  // namespace cranioplan
