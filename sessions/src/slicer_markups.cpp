#include "cranioplan/sessions/slicer_markups.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <optional>
#include <set>

#include "cranioplan/model/error.h"

namespace cranioplan {
namespace {

constexpr const char* kSchema =
    "https://raw.githubusercontent.com/slicer/slicer/master/Modules/Loadable/Markups/Resources/"
    "Schema/markups-schema-v1.0.3.json#";

constexpr MarkerType kTypes[] = {MarkerType::OuterEdge, MarkerType::InnerEdge,
                                 MarkerType::OuterSurface, MarkerType::InnerSurface};

// Lower case, with '_' and '-' read as spaces and runs of spaces as one.
std::string normalised(const std::string& text) {
  std::string out;
  for (char c : text) {
    char l = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    if (l == '_' || l == '-') l = ' ';
    if (l == ' ' && (out.empty() || out.back() == ' ')) continue;
    out += l;
  }
  while (!out.empty() && out.back() == ' ') out.pop_back();
  return out;
}

std::optional<MarkerType> type_named_in(const std::string& text) {
  const std::string n = normalised(text);
  for (MarkerType t : kTypes)
    if (n.find(to_string(t)) != std::string::npos) return t;
  return std::nullopt;
}

Json control_point(const std::string& id, const std::string& label, const std::string& description,
                   const Eigen::Vector3d& p) {
  return Json{{"id", id},
              {"label", label},
              {"description", description},
              {"position", {p.x(), p.y(), p.z()}},
              {"positionStatus", "defined"}};
}

Json fiducial_list(const std::string& name, Json points) {
  return Json{{"type", "Fiducial"},
              {"name", name},
              {"coordinateSystem", "LPS"},
              {"coordinateUnits", "mm"},
              {"controlPoints", std::move(points)}};
}

Json markups_file(Json lists) { return Json{{"@schema", kSchema}, {"markups", std::move(lists)}}; }

// A point of a fiducial list as read: where it is (LPS, mm), its label, id and description.
struct ReadPoint {
  std::string list_name, label, id, description;
  Eigen::Vector3d position;
  std::string where;  // "list 'F', point 3", for messages
};

std::string string_field(const Json& j, const char* key) {
  return j.contains(key) && j[key].is_string() ? j[key].get<std::string>() : std::string();
}

// Every defined point of every fiducial list, in LPS millimetres. None is an error unless
// `may_be_empty`.
std::vector<ReadPoint> read_points(const Json& j, const std::string& source, bool may_be_empty) {
  if (!j.is_object() || !j.contains("markups") || !j["markups"].is_array())
    throw InputError(source, "not a Slicer markups file: expected {\"markups\": [...]}");
  std::vector<ReadPoint> out;
  std::set<std::string> other_types;
  int list_no = 0;
  for (const Json& m : j["markups"]) {
    ++list_no;
    const std::string type = m.is_object() ? string_field(m, "type") : std::string();
    if (type != "Fiducial") {
      other_types.insert(type.empty() ? "(no type)" : type);
      continue;
    }
    const std::string name = string_field(m, "name");
    const std::string list = "list " + (name.empty() ? std::to_string(list_no) : "'" + name + "'");
    const std::string system =
        m.contains("coordinateSystem") ? string_field(m, "coordinateSystem") : std::string("LPS");
    if (system != "LPS" && system != "RAS")
      throw InputError(source,
                       list + ": coordinate system must be LPS or RAS, not '" + system + "'");
    double scale = 1.0;
    if (m.contains("coordinateUnits")) {
      const Json& u = m["coordinateUnits"];
      const std::string unit = u.is_array() && !u.empty() && u[0].is_string()
                                   ? u[0].get<std::string>()
                                   : string_field(m, "coordinateUnits");
      if (unit == "um")
        scale = 1e-3;
      else if (unit != "mm")
        throw InputError(source, list + ": coordinate units must be mm or um, not '" + unit + "'");
    }
    if (!m.contains("controlPoints")) continue;
    if (!m["controlPoints"].is_array())
      throw InputError(source, list + ": controlPoints is not a list");
    int point_no = 0;
    for (const Json& p : m["controlPoints"]) {
      const std::string where = list + ", point " + std::to_string(++point_no);
      if (!p.is_object()) throw InputError(source, where + " is not an object");
      const std::string status = string_field(p, "positionStatus");
      if (!status.empty() && status != "defined") continue;  // undefined, preview, missing
      Eigen::Vector3d pos = vector_from_json(p.contains("position") ? p["position"] : Json(),
                                             source, where + " position");
      pos *= scale;
      if (system == "RAS") pos = Eigen::Vector3d(-pos.x(), -pos.y(), pos.z());
      out.push_back({name, string_field(p, "label"), string_field(p, "id"),
                     string_field(p, "description"), pos, where});
    }
  }
  if (out.empty() && !may_be_empty) {
    std::string what = "no defined point in a fiducial list";
    if (!other_types.empty()) {
      what += " (it holds ";
      for (const std::string& t : other_types) what += (what.back() == ' ' ? "" : ", ") + t;
      what += " markups, which are not read)";
    }
    throw InputError(source, what);
  }
  return out;
}

std::optional<int> whole_number(const std::string& text) {
  if (text.empty() || text.size() > 9 ||
      !std::all_of(text.begin(), text.end(), [](char c) { return std::isdigit(c); }))
    return std::nullopt;
  const int v = std::stoi(text);
  return v > 0 ? std::optional<int>(v) : std::nullopt;
}

}  // namespace

bool is_markups_path(const std::string& path) {
  const std::string n = normalised(path.size() >= 9 ? path.substr(path.size() - 9) : path);
  return n == ".mrk.json";
}

Json markers_to_markups(const std::vector<Marker>& markers) {
  Json lists = Json::array();
  for (MarkerType t : kTypes) {
    Json points = Json::array();
    for (const Marker& m : markers)
      if (m.type == t)
        points.push_back(control_point(std::to_string(m.id),
                                       std::string(to_string(t)) + " " + std::to_string(m.id),
                                       to_string(m.surface), m.position));
    if (!points.empty()) lists.push_back(fiducial_list(to_string(t), std::move(points)));
  }
  return markups_file(std::move(lists));
}

std::vector<Marker> markers_from_markups(const Json& j, const std::string& source) {
  const std::vector<ReadPoint> points = read_points(j, source, false);
  std::vector<Marker> out;
  std::set<int> used;
  for (const ReadPoint& p : points) {
    std::optional<MarkerType> type = type_named_in(p.list_name);
    if (!type) type = type_named_in(p.label);
    if (!type)
      throw InputError(source, p.where +
                                   " does not say which marker it is: name the list, or "
                                   "label the point, 'outer edge', 'inner edge', 'outer "
                                   "surface' or 'inner surface'");
    Marker m;
    m.type = *type;
    m.position = p.position;
    const std::string surface = normalised(p.description);
    m.surface = surface == "mirrored"   ? MarkerSurface::Mirrored
                : surface == "original" ? MarkerSurface::Original
                                        : default_surface(m.type);
    const std::optional<int> id = whole_number(p.id);
    m.id = id && !used.count(*id) ? *id : 0;
    if (m.id) used.insert(m.id);
    out.push_back(m);
  }
  // Points without a usable id take the next free ones, in file order.
  int next = used.empty() ? 1 : *used.rbegin() + 1;
  for (Marker& m : out)
    if (m.id == 0) m.id = next++;
  return out;
}

Json landmarks_to_markups(const Landmarks& lm) {
  Json points = Json::array();
  const std::pair<const char*, const std::optional<Eigen::Vector3d>*> named[] = {
      {"nasion", &lm.nasion}, {"orbit_left", &lm.orbit_left}, {"orbit_right", &lm.orbit_right}};
  for (const auto& [name, p] : named)
    if (*p) points.push_back(control_point(name, name, "", **p));
  for (size_t i = 0; i < lm.midline.size(); ++i) {
    const std::string label = "midline-" + std::to_string(i + 1);
    points.push_back(control_point(label, label, "", lm.midline[i]));
  }
  Json lists = Json::array();
  if (!points.empty()) lists.push_back(fiducial_list("landmarks", std::move(points)));
  return markups_file(std::move(lists));
}

Landmarks landmarks_from_markups(const Json& j, const std::string& source) {
  Landmarks lm;
  for (const ReadPoint& p : read_points(j, source, true)) {
    const std::string label = normalised(p.label);
    std::optional<Eigen::Vector3d>* slot = nullptr;
    if (label == "nasion")
      slot = &lm.nasion;
    else if (label == "orbit left" || label == "left orbit")
      slot = &lm.orbit_left;
    else if (label == "orbit right" || label == "right orbit")
      slot = &lm.orbit_right;
    if (slot) {
      if (*slot) throw InputError(source, p.where + ": a second '" + p.label + "'");
      *slot = p.position;
    } else if (label.rfind("midline", 0) == 0) {
      lm.midline.push_back(p.position);
    } else {
      throw InputError(source, p.where + " is labelled '" + p.label +
                                   "': landmarks are labelled nasion, orbit_left, orbit_right "
                                   "or midline");
    }
  }
  return lm;
}

}  // namespace cranioplan
