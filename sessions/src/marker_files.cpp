#include "cranioplan/sessions/marker_files.h"

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <set>
#include <sstream>

#include "cranioplan/algorithms/io/file_io.h"
#include "cranioplan/model/error.h"
#include "cranioplan/sessions/slicer_markups.h"

namespace cranioplan {
namespace {

MarkerSurface surface_from_text(const std::string& text, const std::string& source,
                                const std::string& where) {
  if (text == "original") return MarkerSurface::Original;
  if (text == "mirrored") return MarkerSurface::Mirrored;
  throw InputError(source,
                   where + ": surface must be \"original\" or \"mirrored\", not \"" + text + "\"");
}

void check_unique(const std::vector<Marker>& markers, const std::string& source) {
  std::set<int> ids;
  for (const auto& m : markers)
    if (!ids.insert(m.id).second)
      throw InputError(source, "marker id " + std::to_string(m.id) + " is used twice");
}

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return s;
}

}  // namespace

Json to_json(const Marker& m) {
  return Json{{"id", m.id},
              {"type", static_cast<int>(m.type)},
              {"position", to_json(m.position)},
              {"surface", to_string(m.surface)}};
}

Json markers_to_json(const std::vector<Marker>& markers) {
  Json list = Json::array();
  for (const auto& m : markers) list.push_back(to_json(m));
  return Json{{"markers", list}};
}

std::vector<Marker> markers_from_json(const Json& j, const std::string& source) {
  if (!j.is_object() || !j.contains("markers") || !j["markers"].is_array())
    throw InputError(source, "expected {\"markers\": [...]}");
  std::vector<Marker> out;
  int index = 0;
  for (const auto& e : j["markers"]) {
    const std::string where = "marker " + std::to_string(++index);
    if (!e.is_object()) throw InputError(source, where + " is not an object");
    for (const char* key : {"id", "type", "position"})
      if (!e.contains(key)) throw InputError(source, where + " has no \"" + key + "\"");
    if (!e["id"].is_number_integer()) throw InputError(source, where + ": id must be an integer");
    if (!e["type"].is_number_integer() || e["type"].get<int>() < 0 || e["type"].get<int>() > 3)
      throw InputError(source, where + ": type must be 0, 1, 2 or 3");
    Marker m;
    m.id = e["id"].get<int>();
    m.type = static_cast<MarkerType>(e["type"].get<int>());
    m.position = vector_from_json(e["position"], source, where + " position");
    m.surface = default_surface(m.type);
    if (e.contains("surface")) {
      if (!e["surface"].is_string()) throw InputError(source, where + ": surface must be a string");
      m.surface = surface_from_text(e["surface"].get<std::string>(), source, where);
    }
    out.push_back(m);
  }
  check_unique(out, source);
  return out;
}

std::vector<Marker> read_markers_file(const std::string& path) {
  if (is_markups_path(path)) return markers_from_markups(read_json_file(path), path);
  const std::string name = lower(path);
  if (name.size() >= 4 && name.substr(name.size() - 4) == ".csv") {
    std::istringstream in(read_file_bytes(path));
    std::string line;
    std::vector<Marker> out;
    int line_no = 0;
    while (std::getline(in, line)) {
      ++line_no;
      if (!line.empty() && line.back() == '\r') line.pop_back();
      if (line.empty() || line[0] == '#' || (line_no == 1 && lower(line).rfind("id", 0) == 0))
        continue;
      std::replace(line.begin(), line.end(), ',', ' ');
      std::istringstream fields(line);
      Marker m;
      int type = -1;
      std::string surface;
      if (!(fields >> m.id >> type >> m.position.x() >> m.position.y() >> m.position.z()) ||
          type < 0 || type > 3 || !m.position.allFinite())
        throw InputError(
            path, "line " + std::to_string(line_no) + ": expected id,type(0-3),x,y,z[,surface]");
      m.type = static_cast<MarkerType>(type);
      m.surface = fields >> surface
                      ? surface_from_text(surface, path, "line " + std::to_string(line_no))
                      : default_surface(m.type);
      out.push_back(m);
    }
    if (out.empty()) throw InputError(path, "holds no markers");
    check_unique(out, path);
    return out;
  }
  return markers_from_json(read_json_file(path), path);
}

void write_markers_file(const std::vector<Marker>& markers, const std::string& path) {
  if (is_markups_path(path)) return write_json_file(markers_to_markups(markers), path);
  const std::string name = lower(path);
  if (name.size() >= 4 && name.substr(name.size() - 4) == ".csv") {
    std::string text = "id,type,x,y,z,surface\n";
    char buf[256];
    for (const auto& m : markers) {
      std::snprintf(buf, sizeof(buf), "%d,%d,%.17g,%.17g,%.17g,%s\n", m.id,
                    static_cast<int>(m.type), m.position.x(), m.position.y(), m.position.z(),
                    to_string(m.surface));
      text += buf;
    }
    write_file_atomically(path, text);
    return;
  }
  write_json_file(markers_to_json(markers), path);
}

}  // namespace cranioplan
