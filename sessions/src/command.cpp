#include "cranioplan/sessions/command.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <limits>

#include "cranioplan/algorithms/io/write_mesh.h"
#include "cranioplan/model/error.h"
#include "cranioplan/sessions/marker_files.h"
#include "cranioplan/sessions/session_error.h"
#include "cranioplan/sessions/sha256.h"
#include "cranioplan/sessions/steps.h"

namespace cranioplan {

namespace {

struct TypeInfo {
  CommandType type;
  const char* tag;
  std::vector<const char*> required;  ///< parameters every version-1 command carries
};

const std::vector<TypeInfo>& type_table() {
  static const std::vector<TypeInfo> table = {
      {CommandType::LoadSkull, "load_skull", {"path", "sha256", "import"}},
      {CommandType::SetLandmark, "set_landmark", {"name", "position"}},
      {CommandType::ClearLandmark, "clear_landmark", {"name"}},
      {CommandType::FitPlane, "fit_plane", {"params"}},
      {CommandType::AdjustPlane, "adjust_plane", {"axis", "angle_deg", "shift_mm"}},
      {CommandType::Mirror, "mirror", {}},
      {CommandType::Register, "register", {"params"}},
      {CommandType::MoveMirrored, "move_mirrored", {"axis", "angle_deg", "center", "translation"}},
      {CommandType::SetClipPlane, "set_clip_plane", {"enabled"}},
      {CommandType::AddMarker, "add_marker", {"type", "position"}},
      {CommandType::MoveMarker, "move_marker", {"id", "position"}},
      {CommandType::DeleteMarker, "delete_marker", {"id"}},
      {CommandType::RetypeMarker, "retype_marker", {"id", "type"}},
      {CommandType::ImportMarkers, "import_markers", {"source", "sha256", "markers"}},
      {CommandType::ClearMarkers, "clear_markers", {}},
      {CommandType::ProposeMarkers, "propose_markers", {"params"}},
      {CommandType::SmoothMarkers, "smooth_markers", {"params", "project_onto_mirror"}},
      {CommandType::BuildImplant, "build_implant", {"params"}},
      {CommandType::ExportImplant, "export_implant", {"path", "format", "sha256"}},
      {CommandType::GoToStep, "go_to_step", {"step"}},
      {CommandType::CompleteStep, "complete_step", {"step"}},
      {CommandType::Note, "note", {"text"}},
      {CommandType::AttachCt, "attach_ct", {"path", "sha256", "import"}},
      {CommandType::Approve, "approve", {"by", "role", "implant_sha256"}},
  };
  return table;
}

const TypeInfo& info(CommandType type) {
  for (const auto& t : type_table())
    if (t.type == type) return t;
  assert(false && "every CommandType has a row in type_table()");
  return type_table().front();
}

Json number_or_null(double v) { return std::isfinite(v) ? Json(v) : Json(nullptr); }

// Visitors over a Params struct's fields, both directions: the fields a struct declares
// (for_each_field, ParamSpec) and the lists below of those not declared yet (field(name)).
struct DeclaredWriter {
  Json& j;
  void operator()(const ParamSpec& s, const double& v) { j[s.key] = number_or_null(v); }
  void operator()(const ParamSpec& s, const int& v) { j[s.key] = v; }
  void operator()(const ParamSpec& s, const long long& v) { j[s.key] = v; }
  void operator()(const ParamSpec& s, const bool& v) { j[s.key] = v; }
  void operator()(const ParamSpec& s, const std::string& v) { j[s.key] = v; }
  void operator()(const ParamSpec& s, const Eigen::Vector3d& v) { j[s.key] = to_json(v); }
  void operator()(const ParamSpec& s, const std::vector<Eigen::Vector3d>& points) {
    Json list = Json::array();
    for (const auto& v : points) list.push_back(to_json(v));
    j[s.key] = list;
  }
  void operator()(const ParamSpec& s, const std::optional<Plane>& plane) {
    j[s.key] =
        plane ? Json{{"normal", to_json(plane->normal)}, {"offset", plane->offset}} : Json(nullptr);
  }
};

struct DeclaredReader {
  static constexpr size_t kMaxPoints = 1000;
  const ParamReader& r;
  void operator()(const ParamSpec& s, double& v) { v = r.number(s.key); }
  void operator()(const ParamSpec& s, int& v) { v = r.integer(s.key); }
  void operator()(const ParamSpec& s, long long& v) {
    v = static_cast<long long>(std::llround(r.number(s.key)));
  }
  void operator()(const ParamSpec& s, bool& v) { v = r.boolean(s.key); }
  void operator()(const ParamSpec& s, std::string& v) { v = r.string(s.key); }
  void operator()(const ParamSpec& s, Eigen::Vector3d& v) { v = r.vector3(s.key); }
  void operator()(const ParamSpec& s, std::vector<Eigen::Vector3d>& points) {
    const Json& list = r.value(s.key);
    if (!list.is_array()) throw SessionError(r.where(), std::string(s.key) + " must be a list");
    if (list.size() > kMaxPoints)
      throw SessionError(r.where(),
                         "more than " + format_count(kMaxPoints) + " points in " + s.key);
    for (const Json& v : list)
      points.push_back(vector_from_json(v, r.where(), std::string("a point in ") + s.key));
  }
  void operator()(const ParamSpec& s, std::optional<Plane>& plane) {
    plane.reset();
    if (r.value(s.key).is_null()) return;
    const ParamReader m(r.value(s.key), r.where() + " " + s.key);
    plane = Plane{m.vector3("normal"), m.number("offset")};
  }
};

template <class V, class P>
void extract_fields(V& v, P& p) {
  v(field("threshold"), p.threshold);
  v(field("largest_piece_only"), p.largest_piece_only);
  v(field("min_piece_triangles"), p.min_piece_triangles);
  v(field("target_triangles"), p.target_triangles);
}

template <class V, class P>
void detect_fields(V& v, P& p) {
  v(field("directions"), p.directions);
  v(field("min_area_mm2"), p.min_area_mm2);
  v(field("support_width_mm"), p.support_width_mm);
  v(field("max_thickness_mm"), p.max_thickness_mm);
  v(field("min_thickness_mm"), p.min_thickness_mm);
}

template <class V, class P>
void propose_fields(V& v, P& p) {
  v(field("min_mirror_coverage"), p.min_mirror_coverage);
  v(field("edge_spacing_mm"), p.edge_spacing_mm);
  v(field("surface_spacing_mm"), p.surface_spacing_mm);
}

// propose_markers version 2: how the defect's surfaces are fitted to the intact ring.
template <class V, class P>
void surface_fit_fields(V& v, P& p) {
  v(field("ring_width_mm"), p.ring_width_mm);
  v(field("rim_clearance_mm"), p.rim_clearance_mm);
  v(field("ray_spacing_mm"), p.ray_spacing_mm);
  v(field("site_spacing_mm"), p.site_spacing_mm);
  v(field("smoothing"), p.smoothing);
  v(field("outlier_sigmas"), p.outlier_sigmas);
}

// build_implant 3: how the shell is fitted to the bone ("trim").
template <class V, class P>
void trim_fields(V& v, P& p) {
  v(field("voxel_mm"), p.voxel_mm);
  v(field("max_voxels"), p.max_voxels);
  v(field("min_feature_mm"), p.min_feature_mm);
  v(field("smoothing_mm"), p.smoothing_mm);
  v(field("bridge_mm"), p.bridge_mm);
}

template <class Fields, class P>
Json write_fields(Fields fields, const P& p) {
  Json j = Json::object();
  DeclaredWriter w{j};
  fields(w, p);
  return j;
}

template <class P>
Json declared_to_json(const P& p) {
  Json j = Json::object();
  for_each_field(DeclaredWriter{j}, const_cast<P&>(p));  // the writer only reads
  return j;
}

// The fields `p`'s type declares, read into `p` and refused when `problem` (the operation's
// rules, or only the declared ranges) finds one.
template <class P, class Problem>
void read_declared(const ParamReader& r, P& p, Problem problem) {
  for_each_field(DeclaredReader{r}, p);
  if (const std::string why = problem(p); !why.empty()) throw SessionError(r.where(), why);
}

// The same into `P`s of their own; `whose`: the ranges only ("the plane fit's").
template <class P>
P declared_from_json(const ParamReader& r, std::string (*problem)(const P&)) {
  P p;
  read_declared(r, p, problem);
  return p;
}
template <class P>
void read_declared(const ParamReader& r, const char* whose, P& p) {
  read_declared(r, p, [whose](const P& q) { return range_problems(whose, q); });
}

Command make(CommandType type, Json params, int step = 0) {
  Command c;
  c.type = type;
  c.version = current_version(type);
  c.params = std::move(params);
  c.meta.step = step;
  return c;
}

}  // namespace

const std::vector<CommandType>& all_command_types() {
  static const std::vector<CommandType> all = [] {
    std::vector<CommandType> v;
    for (const auto& t : type_table()) v.push_back(t.type);
    return v;
  }();
  return all;
}

const char* type_tag(CommandType type) { return info(type).tag; }

std::optional<CommandType> command_type_from_tag(const std::string& tag) {
  for (const auto& t : type_table())
    if (tag == t.tag) return t.type;
  return std::nullopt;
}

// What each version changed, and how an older one is read: docs/SESSIONS.md, "Command versions".
int current_version(CommandType type) {
  if (type == CommandType::BuildImplant) return 14;
  if (type == CommandType::ExportImplant) return 2;
  if (type == CommandType::ProposeMarkers) return 8;
  if (type == CommandType::LoadSkull) return 6;
  if (type == CommandType::FitPlane || type == CommandType::Register ||
      type == CommandType::AdjustPlane)
    return 2;
  return 1;
}

// ---------------------------------------------------------------------------------------------
// ParamReader

bool ParamReader::has(const char* name) const {
  return params_.is_object() && params_.contains(name);
}

const Json& ParamReader::value(const char* name) const {
  if (!has(name)) throw SessionError(where_, std::string("missing parameter '") + name + "'");
  return params_.at(name);
}

double ParamReader::number(const char* name) const {
  const Json& v = value(name);
  if (v.is_null()) return std::numeric_limits<double>::quiet_NaN();
  if (!v.is_number())
    throw SessionError(where_, std::string("parameter '") + name + "' must be a number");
  return v.get<double>();
}

int ParamReader::integer(const char* name) const {
  const Json& v = value(name);
  if (!v.is_number_integer())
    throw SessionError(where_, std::string("parameter '") + name + "' must be a whole number");
  return v.get<int>();
}

bool ParamReader::boolean(const char* name) const {
  const Json& v = value(name);
  if (!v.is_boolean())
    throw SessionError(where_, std::string("parameter '") + name + "' must be true or false");
  return v.get<bool>();
}

std::string ParamReader::string(const char* name) const {
  const Json& v = value(name);
  if (!v.is_string())
    throw SessionError(where_, std::string("parameter '") + name + "' must be text");
  return v.get<std::string>();
}

Eigen::Vector3d ParamReader::vector3(const char* name) const {
  return vector_from_json(value(name), where_, std::string("parameter '") + name + "'");
}

// ---------------------------------------------------------------------------------------------
// Parameter forms

Json params_to_json(const ExtractBoneSurfaceParams& p) {
  Json j = write_fields([](auto& v, auto& q) { extract_fields(v, q); }, p);
  j["canonical"] = p.canonical;
  j["mesh_unit_mm"] = p.mesh_unit_mm;
  j["orient_outward"] = p.orient_outward;
  j["orient_consistently"] = p.orient_consistently;
  j["drop_repeated_triangles"] = p.drop_repeated_triangles;
  j["close_holes_mm"] = p.close_holes_mm;
  j["close_holes_through_corners"] = p.close_holes_through_corners;
  j["mesh_space_from_header"] = p.mesh_space_from_header;
  j["patient_frame"] = p.patient_frame;
  j["drop_far_pieces"] = p.drop_far_pieces;
  j["dicom_series"] = p.dicom_series;
  return j;
}
Json params_to_json(const PlaneFitParams& p) { return declared_to_json(p); }
Json params_to_json(const SmoothParams& p) { return declared_to_json(p); }

Json params_to_json(const RegisterParams& p) {
  Json j = declared_to_json(p);
  j["initial"] = to_json(p.initial);
  if (p.roi) {
    Json roi;
    roi["shape"] = p.roi->shape == RegionOfInterest::Shape::Sphere ? "sphere" : "box";
    roi["center"] = to_json(p.roi->center);
    roi["radius_mm"] = p.roi->radius;
    roi["half_size_mm"] = to_json(p.roi->half_size);
    j["roi"] = roi;
  } else {
    j["roi"] = nullptr;
  }
  return j;
}

Json params_to_json(const ProposeParams& p) {
  Json j = write_fields([](auto& v, auto& q) { propose_fields(v, q); }, p);
  j["method"] = to_string(p.method);
  j["detect"] = write_fields([](auto& v, auto& q) { detect_fields(v, q); }, p.detect);
  j["detect"]["near"] = p.detect.near ? to_json(*p.detect.near) : Json(nullptr);
  // Written only when set (no plan made in the program sets it), so the commands of every
  // other plan keep their bytes.
  if (p.detect.center) j["detect"]["center"] = to_json(*p.detect.center);
  j["detect"]["trace_rim_on_bone"] = p.detect.trace_rim_on_bone;
  j["detect"]["trace_from_area_mm2"] = p.detect.trace_from_area_mm2;
  j["detect"]["trace_from_unseen_mm"] = p.detect.trace_from_unseen_mm;
  j["smooth"] = params_to_json(p.smooth);
  j["surfaces"] = write_fields([](auto& v, auto& q) { surface_fit_fields(v, q); }, p.surfaces);
  j["surfaces"]["mirror_footprint_mm"] = p.surfaces.mirror_footprint_mm;
  j["surfaces"]["weigh_sites_by_rays"] = p.surfaces.weigh_sites_by_rays;
  j["max_support_off_fit_mm"] = p.max_support_off_fit_mm;
  j["max_support_layers"] = p.max_support_layers;
  return j;
}

Json params_to_json(const ImplantParams& p) {
  Json j = declared_to_json(p);
  j["method"] = to_string(p.method);
  j["frame"] = p.frame == ImplantFrame::Radial ? "radial" : "planar";
  j["radial_center"] = p.radial_center ? to_json(*p.radial_center) : Json(nullptr);
  j["trim"] = write_fields([](auto& v, auto& q) { trim_fields(v, q); }, p.trim);
  j["trim"]["thin_fills_removed"] = p.trim.thin_fills_removed;
  j["trim"]["clearance_mm"] = p.trim.clearance_mm ? Json(*p.trim.clearance_mm) : Json(nullptr);
  j["trim"]["vote_through_holes"] = p.trim.vote_through_holes;
  j["material"] = p.material ? to_json(*p.material) : Json(nullptr);
  j["clearance_zones"] = Json::array();
  for (const ClearanceZone& z : p.clearance_zones) j["clearance_zones"].push_back(to_json(z));
  j["perforations"] = to_json(p.perforations);
  j["tabs"] = to_json(p.tabs);
  j["scan_ends"] = to_json(p.scan_ends);
  return j;
}

Json to_json(const TabParams& p) { return declared_to_json(p); }
Json to_json(const MouldParams& p) { return declared_to_json(p); }
Json to_json(const PerforationParams& p) { return declared_to_json(p); }

MouldParams mould_from_json(const ParamReader& r) { return declared_from_json(r, &mould_problem); }
TabParams tabs_from_json(const ParamReader& r) { return declared_from_json(r, &tab_problem); }
PerforationParams perforations_from_json(const ParamReader& r) {
  return declared_from_json(r, &perforation_problem);
}

Json to_json(const Material& m) { return declared_to_json(m); }

Json to_json(const ClearanceZone& z) { return declared_to_json(z); }

Material material_from_json(const ParamReader& r) {
  Material m;
  for_each_field(DeclaredReader{r}, m);
  if (const std::string problem = material_problem(m); !problem.empty())
    throw SessionError(r.where(), "material " + m.name + ": " + problem);
  return m;
}

ClearanceZone clearance_zone_from_json(const ParamReader& r) {
  return declared_from_json(r, &zone_problem);
}

void params_from_json(const ParamReader& r, ExtractBoneSurfaceParams& p) {
  DeclaredReader v{r};
  extract_fields(v, p);
  // load_skull 1 has no "canonical": the skull as the file gave it, so that
  // those plans replay to the implants they exported.
  p.canonical = r.has("canonical") && r.boolean("canonical");
  // load_skull 1 and 2 read every mesh in millimetres.
  p.mesh_unit_mm = r.has("mesh_unit_mm") ? r.number("mesh_unit_mm") : 1.0;
  if (!(p.mesh_unit_mm > 0.0) || !std::isfinite(p.mesh_unit_mm))
    throw SessionError(r.where(), "parameter 'mesh_unit_mm' must be a positive length in mm");
  // Nor did they turn a skull that winds inward outward.
  p.orient_outward = r.has("orient_outward") && r.boolean("orient_outward");
  // Before load_skull 5, nor patches that wind against their neighbours turned to agree.
  p.orient_consistently = r.has("orient_consistently") && r.boolean("orient_consistently");
  p.drop_repeated_triangles =
      r.has("drop_repeated_triangles") && r.boolean("drop_repeated_triangles");
  p.close_holes_mm = r.has("close_holes_mm") ? r.number("close_holes_mm") : 0.0;
  if (!(p.close_holes_mm >= 0.0) || !std::isfinite(p.close_holes_mm))
    throw SessionError(r.where(), "parameter 'close_holes_mm' must be a length ≥ 0 in mm");
  // Before load_skull 6, holes that touch another at a corner were left open.
  p.close_holes_through_corners =
      r.has("close_holes_through_corners") && r.boolean("close_holes_through_corners");
  // Nor did they read a mesh's declared RAS coordinates in LPS.
  p.mesh_space_from_header = r.has("mesh_space_from_header") && r.boolean("mesh_space_from_header");
  // Before load_skull 4, a NRRD's or NIfTI's positions were read as the file writes them (NIfTI
  // in RAS), and a mesh's far pieces were kept.
  p.patient_frame = r.has("patient_frame") && r.boolean("patient_frame");
  p.drop_far_pieces = r.has("drop_far_pieces") && r.boolean("drop_far_pieces");
  p.dicom_series = r.has("dicom_series") ? r.string("dicom_series") : std::string();
}
void params_from_json(const ParamReader& r, PlaneFitParams& p) {
  read_declared(r, "the plane fit's", p);
}
void params_from_json(const ParamReader& r, SmoothParams& p) {
  p = declared_from_json(r, &smooth_problem);
}

void params_from_json(const ParamReader& r, RegisterParams& p) {
  read_declared(r, "the registration's", p);
  p.initial = transform_from_json(r.value("initial"), r.where());
  const Json& roi = r.value("roi");
  if (roi.is_null()) {
    p.roi.reset();
    return;
  }
  const ParamReader rr(roi, r.where() + " roi");
  RegionOfInterest region;
  const std::string shape = rr.string("shape");
  if (shape != "sphere" && shape != "box")
    throw SessionError(r.where(), "roi shape must be \"sphere\" or \"box\", not \"" + shape + "\"");
  region.shape = shape == "sphere" ? RegionOfInterest::Shape::Sphere : RegionOfInterest::Shape::Box;
  region.center = rr.vector3("center");
  region.radius = rr.number("radius_mm");
  region.half_size = rr.vector3("half_size_mm");
  p.roi = region;
}

void params_from_json(const ParamReader& r, ProposeParams& p) {
  DeclaredReader v{r};
  propose_fields(v, p);
  const std::string method = r.string("method");
  if (!plan_method_from_string(method, p.method))
    throw SessionError(r.where(), "unknown planning method \"" + method + "\"");
  const ParamReader detect(r.value("detect"), r.where() + " detect");
  DeclaredReader dv{detect};
  detect_fields(dv, p.detect);
  p.detect.near.reset();
  if (detect.has("near") && !detect.value("near").is_null()) p.detect.near = detect.vector3("near");
  p.detect.center.reset();
  if (detect.has("center")) p.detect.center = detect.vector3("center");
  // Versions 1 to 6 have none: the rim the rays saw, never traced on the bone.
  p.detect.trace_rim_on_bone =
      detect.has("trace_rim_on_bone") && detect.boolean("trace_rim_on_bone");
  if (detect.has("trace_from_area_mm2"))
    p.detect.trace_from_area_mm2 = detect.number("trace_from_area_mm2");
  if (detect.has("trace_from_unseen_mm"))
    p.detect.trace_from_unseen_mm = detect.number("trace_from_unseen_mm");
  params_from_json(ParamReader(r.value("smooth"), r.where() + " smooth"), p.smooth);
  // Version 1 (before the surfaces were fitted to the ring) has no "surfaces": the defaults.
  // Versions 1 to 4 read the mirror along one ray: no footprint. Versions 1 to 5 weigh every
  // fitting site alike.
  p.surfaces.mirror_footprint_mm = 0.0;
  p.surfaces.weigh_sites_by_rays = false;
  if (r.has("surfaces")) {
    const ParamReader surfaces(r.value("surfaces"), r.where() + " surfaces");
    DeclaredReader sv{surfaces};
    surface_fit_fields(sv, p.surfaces);
    if (surfaces.has("mirror_footprint_mm"))
      p.surfaces.mirror_footprint_mm = surfaces.number("mirror_footprint_mm");
    if (surfaces.has("weigh_sites_by_rays"))
      p.surfaces.weigh_sites_by_rays = surfaces.boolean("weigh_sites_by_rays");
  }
  // Versions 1 to 3 have none: support markers on every ring point of the band (0: off).
  p.max_support_off_fit_mm =
      r.has("max_support_off_fit_mm") ? r.number("max_support_off_fit_mm") : 0.0;
  // Versions 1 to 6 have none: inner support markers however thick the ring's bone (0: off).
  p.max_support_layers = r.has("max_support_layers") ? r.number("max_support_layers") : 0.0;
}

void params_from_json(const ParamReader& r, ImplantParams& p) {
  read_declared(r, "the implant's", p);
  const std::string method = r.string("method");
  if (method == to_string(ImplantMethod::Shell))
    p.method = ImplantMethod::Shell;
  else if (method == to_string(ImplantMethod::Delaunay3D))
    p.method = ImplantMethod::Delaunay3D;
  else
    throw SessionError(r.where(), "unknown implant method \"" + method + "\"");
  const std::string frame = r.string("frame");
  if (frame != "radial" && frame != "planar")
    throw SessionError(r.where(), "implant frame must be \"radial\" or \"planar\"");
  p.frame = frame == "radial" ? ImplantFrame::Radial : ImplantFrame::Planar;
  const Json& c = r.value("radial_center");
  p.radial_center.reset();
  if (!c.is_null()) p.radial_center = vector_from_json(c, r.where(), "radial_center");
  // build_implant 1 and 2 have no "trim": the fit to the bone they were made with (slivers
  // under 1.25 mm removed, cracks under 2 mm bridged), so that those plans replay to their
  // implants.
  p.trim = TrimToBoneParams{};
  if (r.has("trim")) {
    const ParamReader trim(r.value("trim"), r.where() + " trim");
    DeclaredReader tv{trim};
    trim_fields(tv, p.trim);
    // build_implant 3 has no "clearance_mm": the bone grown by a voxel kept out,
    // and fills kept as made.
    p.trim.thin_fills_removed =
        trim.has("thin_fills_removed") && trim.boolean("thin_fills_removed");
    p.trim.vote_through_holes =
        trim.has("vote_through_holes") && trim.boolean("vote_through_holes");
    p.trim.clearance_mm.reset();
    if (trim.has("clearance_mm") && !trim.value("clearance_mm").is_null()) {
      const double c = trim.number("clearance_mm");
      if (!std::isfinite(c) || c < 0)
        throw SessionError(trim.where(), "clearance_mm must be a distance of 0 mm or more");
      p.trim.clearance_mm = c;
    }
  } else {
    p.trim.thin_fills_removed = false;
    p.trim.vote_through_holes = false;
    p.trim.clearance_mm.reset();
    p.trim.min_feature_mm = 1.25;
    p.trim.bridge_mm = 1.0;
  }
  // build_implant 5 and before have no material and no clearance zones.
  p.material.reset();
  if (r.has("material") && !r.value("material").is_null())
    p.material = material_from_json(ParamReader(r.value("material"), r.where() + " material"));
  p.perforations = PerforationParams{};
  if (r.has("perforations"))
    p.perforations =
        perforations_from_json(ParamReader(r.value("perforations"), r.where() + " perforations"));
  // build_implant 6 and before have no tabs.
  p.tabs = TabParams{};
  if (r.has("tabs")) p.tabs = tabs_from_json(ParamReader(r.value("tabs"), r.where() + " tabs"));
  // build_implant 13 and before have no scan ends.
  p.scan_ends.clear();
  if (r.has("scan_ends")) p.scan_ends = planes_from_json(r.value("scan_ends"), r.where());
  p.clearance_zones.clear();
  if (r.has("clearance_zones")) {
    const Json& zones = r.value("clearance_zones");
    if (!zones.is_array()) throw SessionError(r.where(), "clearance_zones must be a list");
    for (size_t k = 0; k < zones.size(); ++k)
      p.clearance_zones.push_back(clearance_zone_from_json(
          ParamReader(zones[k], r.where() + " clearance zone " + std::to_string(k + 1))));
  }
}

// ---------------------------------------------------------------------------------------------
// Commands as JSON

Json to_json(const Command& c) {
  Json j;
  j["type"] = type_tag(c.type);
  j["version"] = c.version;
  j["params"] = c.params;
  Json meta;
  meta["step"] = c.meta.step;
  meta["started"] = c.meta.started;
  meta["ended"] = c.meta.ended;
  meta["duration_ms"] = c.meta.duration_ms;
  meta["user"] = c.meta.user;
  j["meta"] = meta;
  return j;
}

Command command_from_json(const Json& j, const std::string& where) {
  if (!j.is_object()) throw SessionError(where, "a command must be a JSON object");
  const ParamReader top(j, where);
  const std::string tag = top.string("type");
  const auto type = command_type_from_tag(tag);
  if (!type) throw SessionError(where, "unknown command type \"" + tag + "\"");
  Command c;
  c.type = *type;
  c.version = top.integer("version");
  if (c.version < 1 || c.version > current_version(*type))
    throw SessionError(where, "command \"" + tag + "\" version " + std::to_string(c.version) +
                                  " is newer than this program knows (" +
                                  std::to_string(current_version(*type)) + ")");
  c.params = top.value("params");
  if (!c.params.is_object()) throw SessionError(where, "\"params\" must be a JSON object");
  const std::string cw = where + " (" + tag + ")";
  const ParamReader params(c.params, cw);
  for (const char* name : info(*type).required) params.value(name);
  const ParamReader meta(top.value("meta"), where + " meta");
  c.meta.step = meta.integer("step");
  c.meta.started = meta.string("started");
  c.meta.ended = meta.string("ended");
  c.meta.duration_ms = meta.number("duration_ms");
  c.meta.user = meta.string("user");
  return c;
}

std::string describe(const Command& c) {
  const Json& p = c.params;
  auto id = [&] {
    return p.contains("id") ? std::to_string(p["id"].get<int>()) : std::string("?");
  };
  auto marker_type = [&] {
    const int t = p.contains("type") && p["type"].is_number_integer() ? p["type"].get<int>() : 0;
    return std::string(to_string(static_cast<MarkerType>(std::clamp(t, 0, 3))));
  };
  switch (c.type) {
    case CommandType::LoadSkull:
      return "Load skull " + p.value("path", std::string());
    case CommandType::SetLandmark:
      return "Set landmark " + p.value("name", std::string());
    case CommandType::ClearLandmark:
      return "Clear landmark " + p.value("name", std::string());
    case CommandType::FitPlane:
      return "Fit midsagittal plane";
    case CommandType::AdjustPlane:
      return "Adjust plane by hand";
    case CommandType::Mirror:
      return "Mirror skull";
    case CommandType::Register:
      return "Register mirrored skull";
    case CommandType::MoveMirrored:
      return "Move mirrored skull by hand";
    case CommandType::SetClipPlane:
      return p.value("enabled", false) ? "Set clip plane" : "Remove clip plane";
    case CommandType::AddMarker:
      return "Add " + marker_type() + " marker";
    case CommandType::MoveMarker:
      return "Move marker " + id();
    case CommandType::DeleteMarker:
      return "Delete marker " + id();
    case CommandType::RetypeMarker:
      return "Make marker " + id() + " " + marker_type();
    case CommandType::ImportMarkers:
      return "Import markers from " + p.value("source", std::string());
    case CommandType::ClearMarkers:
      return "Clear markers";
    case CommandType::ProposeMarkers:
      return "Propose markers automatically";
    case CommandType::SmoothMarkers:
      return "Smooth markers";
    case CommandType::BuildImplant:
      return "Build implant (" +
             (p.contains("params") ? p["params"].value("method", std::string("shell"))
                                   : std::string("shell")) +
             ")";
    case CommandType::ExportImplant:
      return "Export implant to " + p.value("path", std::string());
    case CommandType::GoToStep:
      return "Go to step " + std::to_string(p.value("step", 0));
    case CommandType::CompleteStep:
      return "Complete step " + std::to_string(p.value("step", 0));
    case CommandType::Note:
      return "Note: " + p.value("text", std::string());
    case CommandType::AttachCt:
      return "Attach CT " + p.value("path", std::string());
    case CommandType::Approve:
      return "Approved by " + p.value("by", std::string()) + " (" + p.value("role", std::string()) +
             ")";
  }
  return type_tag(c.type);
}

// ---------------------------------------------------------------------------------------------
// Builders

namespace commands {

Command attach_ct(const std::string& path, const ExtractBoneSurfaceParams& import,
                  const std::string& sha256) {
  return make(CommandType::AttachCt,
              {{"path", path}, {"sha256", sha256}, {"import", params_to_json(import)}}, 0);
}

Command load_skull(const std::string& path, const ExtractBoneSurfaceParams& import,
                   const std::string& sha256) {
  return make(CommandType::LoadSkull,
              {{"path", path}, {"sha256", sha256}, {"import", params_to_json(import)}}, kLoadStep);
}

Command set_landmark(const std::string& name, const Eigen::Vector3d& position) {
  return make(CommandType::SetLandmark, {{"name", name}, {"position", to_json(position)}},
              kPlaneStep);
}

Command clear_landmark(const std::string& name) {
  return make(CommandType::ClearLandmark, {{"name", name}}, kPlaneStep);
}

Command fit_plane(const PlaneFitParams& params) {
  return make(CommandType::FitPlane, {{"params", params_to_json(params)}}, kPlaneStep);
}

Command adjust_plane(const Eigen::Vector3d& axis, double angle_deg, double shift_mm) {
  return make(CommandType::AdjustPlane,
              {{"axis", to_json(axis)}, {"angle_deg", angle_deg}, {"shift_mm", shift_mm}},
              kPlaneStep);
}

Command mirror() { return make(CommandType::Mirror, Json::object(), kMirrorStep); }

Command register_mirror(const RegisterParams& params) {
  return make(CommandType::Register, {{"params", params_to_json(params)}}, kMirrorStep);
}

Command move_mirrored(const Eigen::Vector3d& axis, double angle_deg, const Eigen::Vector3d& center,
                      const Eigen::Vector3d& translation) {
  return make(CommandType::MoveMirrored,
              {{"axis", to_json(axis)},
               {"angle_deg", angle_deg},
               {"center", to_json(center)},
               {"translation", to_json(translation)}},
              kMirrorStep);
}

Command set_clip_plane(const Plane& plane) {
  return make(CommandType::SetClipPlane, {{"enabled", true}, {"plane", to_json(plane)}}, kClipStep);
}

Command clear_clip_plane() {
  return make(CommandType::SetClipPlane, {{"enabled", false}}, kClipStep);
}

Command add_marker(MarkerType type, const Eigen::Vector3d& position) {
  return make(CommandType::AddMarker,
              {{"type", static_cast<int>(type)}, {"position", to_json(position)}},
              is_edge(type) ? kEdgeMarkersStep : kSurfaceMarkersStep);
}

Command move_marker(int id, const Eigen::Vector3d& position) {
  return make(CommandType::MoveMarker, {{"id", id}, {"position", to_json(position)}});
}

Command delete_marker(int id) { return make(CommandType::DeleteMarker, {{"id", id}}); }

Command retype_marker(int id, MarkerType type) {
  return make(CommandType::RetypeMarker, {{"id", id}, {"type", static_cast<int>(type)}});
}

Command import_markers(const std::vector<Marker>& markers, const std::string& source,
                       const std::string& sha256) {
  return make(CommandType::ImportMarkers,
              {{"source", source}, {"sha256", sha256}, {"markers", markers_to_json(markers)}},
              kEdgeMarkersStep);
}

Command clear_markers() {
  return make(CommandType::ClearMarkers, Json::object(), kEdgeMarkersStep);
}

Command propose_markers(const ProposeParams& params, const std::string& shape_model,
                        const std::string& shape_model_sha256, const ShapePriorParams& prior) {
  Json j{{"params", params_to_json(params)}};
  if (!shape_model.empty())
    j["shape_model"] =
        Json{{"path", shape_model},
             {"sha256", shape_model_sha256.empty() ? sha256_file(shape_model) : shape_model_sha256},
             {"weight", params.shape_model_weight},
             {"margin_mm", prior.margin_mm},
             {"noise_mm", prior.fit.noise_mm},
             {"max_rms_mm", prior.fit.max_rms_mm},
             {"min_paired", prior.fit.min_paired}};
  return make(CommandType::ProposeMarkers, j, kEdgeMarkersStep);
}

Command smooth_markers(const SmoothParams& params, bool project_onto_mirror) {
  return make(CommandType::SmoothMarkers,
              {{"params", params_to_json(params)}, {"project_onto_mirror", project_onto_mirror}},
              kSmoothStep);
}

Command build_implant(const ImplantParams& params) {
  return make(CommandType::BuildImplant, {{"params", params_to_json(params)}}, kBuildStep);
}

Command export_implant(const std::string& path, const std::string& sha256,
                       const std::optional<MouldParams>& mould) {
  const MeshFormat format = mesh_format_for_path(path);
  Json params{{"path", path},
              {"format", format == MeshFormat::BinarySTL   ? "stl"
                         : format == MeshFormat::BinaryPLY ? "ply"
                                                           : "3mf"},
              {"sha256", sha256}};
  if (mould) {
    if (format != MeshFormat::ThreeMF)
      throw InputError(path, "a mould is exported in a .3mf package with the implant");
    params["mould"] = to_json(*mould);
  }
  return make(CommandType::ExportImplant, std::move(params), kExportStep);
}

Command approve(const std::string& by, const std::string& role, const std::string& implant_sha256) {
  return make(CommandType::Approve,
              {{"by", by}, {"role", role}, {"implant_sha256", implant_sha256}}, kExportStep);
}

Command go_to_step(int step) { return make(CommandType::GoToStep, {{"step", step}}, step); }

Command complete_step(int step) { return make(CommandType::CompleteStep, {{"step", step}}, step); }

Command note(const std::string& text) { return make(CommandType::Note, {{"text", text}}); }

}  // namespace commands

}  // namespace cranioplan
