#pragma once
// Marker files: JSON {"markers":[{"id":1,"type":0,"position":[x,y,z],"surface":"original"}]},
// CSV with the header id,type,x,y,z,surface, or 3D Slicer markups (.mrk.json,
// slicer_markups.h).
#include <string>
#include <vector>

#include "cranioplan/model/marker.h"
#include "cranioplan/sessions/plan_files.h"

namespace cranioplan {

Json to_json(const Marker& m);
Json markers_to_json(const std::vector<Marker>& markers);
/// Throws InputError naming `source` and the first bad marker. Ids must be unique; types 0–3;
/// surface "original" or "mirrored" (defaults to the type's usual surface when absent).
std::vector<Marker> markers_from_json(const Json& j, const std::string& source);

/// By extension: .mrk.json, .json or .csv. Throws InputError.
std::vector<Marker> read_markers_file(const std::string& path);
void write_markers_file(const std::vector<Marker>& markers, const std::string& path);

}  // namespace cranioplan
