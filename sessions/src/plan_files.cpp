#include "cranioplan/sessions/plan_files.h"

#include <Eigen/LU>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "cranioplan/algorithms/io/file_io.h"
#include "cranioplan/model/error.h"
#include "cranioplan/sessions/slicer_markups.h"

namespace cranioplan {

Json to_json(const Eigen::Vector3d& v) { return Json::array({v.x(), v.y(), v.z()}); }

Json to_json(const Plane& plane) {
  return Json{{"normal", to_json(plane.normal)}, {"offset_mm", plane.offset}};
}

Json to_json(const std::vector<Plane>& planes) {
  Json j = Json::array();
  for (const Plane& p : planes) j.push_back(to_json(p));
  return j;
}

Json to_json(const RigidTransform& t) {
  Json rows = Json::array();
  for (int r = 0; r < 3; ++r) rows.push_back(to_json(Eigen::Vector3d(t.rotation.row(r))));
  return Json{{"rotation", rows}, {"translation", to_json(t.translation)}};
}

Json to_json(const Landmarks& lm) {
  Json j = Json::object();
  if (lm.nasion) j["nasion"] = to_json(*lm.nasion);
  if (lm.orbit_left) j["orbit_left"] = to_json(*lm.orbit_left);
  if (lm.orbit_right) j["orbit_right"] = to_json(*lm.orbit_right);
  if (!lm.midline.empty()) {
    j["midline"] = Json::array();
    for (const auto& p : lm.midline) j["midline"].push_back(to_json(p));
  }
  return j;
}

Json to_json(const MeshReport& r) {
  // The longest loops (a mesh may have thousands of small holes), and every opening described.
  Json loops = Json::array();
  for (size_t i = 0; i < r.loops.size() && i < 20; ++i) {
    const BoundaryLoop& l = r.loops[i];
    loops.push_back({{"edges", l.edges},
                     {"length_mm", l.length_mm},
                     {"centroid", to_json(l.centroid)},
                     {"flatness_mm", l.flatness_mm},
                     {"border", l.at_border ? Json(l.border) : Json(nullptr)}});
  }
  return Json{{"vertices", r.vertices},
              {"boundary_loops", r.loops.size()},
              {"longest_boundary_loops", loops},
              {"openings", describe_openings(r)},
              {"caps", describe_caps(r)},
              {"triangles", r.triangles},
              {"bbox_min", to_json(r.bbox_min)},
              {"bbox_max", to_json(r.bbox_max)},
              {"area_mm2", r.area_mm2},
              {"volume_mm3", r.volume_mm3},
              {"boundary_edges", r.boundary_edges},
              {"nonmanifold_edges", r.nonmanifold_edges},
              {"pieces", r.pieces},
              {"watertight", r.watertight}};
}

namespace {
// The names of PlaneFit::Status and RegisterResult::Status (the same three, in this order).
const char* const kStatusNames[] = {"converged", "max_iterations", "failed"};
}  // namespace

Json to_json(const PlaneFit& fit) {
  return Json{{"normal", to_json(fit.plane.normal)},
              {"offset_mm", fit.plane.offset},
              {"symmetry_rms_mm", fit.symmetry_rms_mm},
              {"inlier_fraction", fit.inlier_fraction},
              {"iterations", fit.iterations},
              {"solver_iterations", fit.solver_iterations},
              {"status", kStatusNames[static_cast<int>(fit.status)]},
              {"message", fit.message},
              {"termination", fit.termination},
              {"initial_method", fit.initial_method},
              {"initial", to_json(fit.initial)},
              {"seconds", fit.seconds}};
}

Json to_json(const RegisterResult& r) {
  Json j = to_json(r.transform);
  j["rms_mm"] = r.rms_mm;
  j["inlier_fraction"] = r.inlier_fraction;
  j["iterations"] = r.iterations;
  j["rotation_deg"] = r.transform.rotation_angle_deg();
  j["status"] = kStatusNames[static_cast<int>(r.status)];
  j["message"] = r.message;
  j["seconds"] = r.seconds;
  return j;
}

Json to_json(const QualityReport& q) {
  Json j{{"watertight", q.watertight},
         {"manifold", q.manifold},
         {"outward", q.outward},
         {"self_intersections", q.self_intersections},
         {"pieces", q.pieces},
         {"volume_mm3", q.volume_mm3},
         {"area_mm2", q.area_mm2},
         {"thickness_min_mm", q.thickness_min_mm},
         {"thickness_median_mm", q.thickness_median_mm},
         {"thickness_max_mm", q.thickness_max_mm},
         {"thin_volume_mm3", q.thin_volume_mm3},
         {"thin_off_bone_mm3", q.thin_off_bone_mm3},
         {"taper_reach_mm", q.taper_reach_mm},
         {"corner_reach_mm", q.corner_reach_mm},
         {"rim_gap_mm", q.rim_gap_mm},
         {"penetration_mm3", q.penetration_mm3},
         {"printable", q.printable},
         {"reasons", q.reasons}};
  // With a material and a clearance asked (build_implant 6) only, so that older reports read
  // as they did.
  if (!q.material_name.empty()) j["material"] = q.material_name;
  if (q.mass_g > 0.0) j["mass_g"] = q.mass_g;
  if (q.holes > 0) {
    j["holes"] = q.holes;
    j["holes_blocked"] = q.holes_blocked;
  }
  if (q.tabs > 0) {
    j["tabs"] = q.tabs;
    j["screws_blocked"] = q.screws_blocked;
    j["tab_gap_mm"] = q.tab_gap_mm;
    j["tab_bone_mm"] = q.tab_bone_mm;
    if (q.tab_midline_mm >= 0) j["tab_midline_mm"] = q.tab_midline_mm;
  }
  if (q.ends_at_scan_end)
    j["ends_at_scan_end"] = true;  // only then: older reports read as they did
  if (q.clearance_asked) {
    j["clearance_low_mm"] = q.clearance_low_mm;
    j["clearance_high_mm"] = q.clearance_high_mm;
  }
  auto xyz = [](const Eigen::Vector3d& p) { return Json::array({p.x(), p.y(), p.z()}); };
  if (q.rim_gap_at && q.rim_gap_bone) {
    j["rim_gap_at_mm"] = xyz(*q.rim_gap_at);
    j["rim_gap_bone_mm"] = xyz(*q.rim_gap_bone);
  }
  return j;
}

Json to_json(const SoftTissueCheck& c) {
  return Json{{"checked", c.checked},
              {"intrusion_mm3", c.intrusion_mm3},
              {"sunken_scalp_mm3", c.sunken_scalp_mm3},
              {"intrusion_reach_mm", c.intrusion_reach_mm},
              {"scalp_mm", c.scalp_mm},
              {"finding", c.finding},
              {"closest_mm", std::isfinite(c.closest_mm) ? Json(c.closest_mm) : Json(nullptr)},
              {"message", c.message}};
}

Json to_json(const CompareResult& c) {
  Json j{{"dice", c.dice}};
  if (c.boundary_dice >= 0) j["boundary_dice"] = c.boundary_dice;
  auto finite = [](double x) { return std::isfinite(x) ? Json(x) : Json(nullptr); };
  j["hausdorff_mm"] = finite(c.hausdorff_mm);
  j["hd95_mm"] = finite(c.hd95_mm);
  j["mean_surface_mm"] = finite(c.mean_surface_mm);
  j["volume_a_mm3"] = c.volume_a_mm3;
  j["volume_b_mm3"] = c.volume_b_mm3;
  j["voxels_a"] = c.voxels_a;
  j["voxels_b"] = c.voxels_b;
  j["voxels_both"] = c.voxels_both;
  j["seconds"] = c.seconds;
  return j;
}

Eigen::Vector3d vector_from_json(const Json& j, const std::string& source,
                                 const std::string& what) {
  if (!j.is_array() || j.size() != 3)
    throw InputError(source, "'" + what + "' must be an array of 3 numbers");
  Eigen::Vector3d v;
  for (int k = 0; k < 3; ++k) {
    if (!j[k].is_number()) throw InputError(source, "'" + what + "' must hold numbers only");
    v[k] = j[k].get<double>();
  }
  if (!v.allFinite()) throw InputError(source, "'" + what + "' holds a value that is not finite");
  return v;
}

Plane plane_from_json(const Json& j, const std::string& source) {
  if (!j.is_object() || !j.contains("normal") || !j.contains("offset_mm"))
    throw InputError(source, "a plane needs 'normal' and 'offset_mm'");
  const Eigen::Vector3d n = vector_from_json(j["normal"], source, "normal");
  if (n.norm() < 1e-9) throw InputError(source, "plane 'normal' must not be zero");
  if (!j["offset_mm"].is_number()) throw InputError(source, "'offset_mm' must be a number");
  const double scale = n.norm();
  return Plane{n / scale, j["offset_mm"].get<double>() / scale};
}

std::vector<Plane> planes_from_json(const Json& j, const std::string& source) {
  if (!j.is_array()) throw InputError(source, "a list of planes must be a list");
  std::vector<Plane> planes;
  for (const Json& one : j) planes.push_back(plane_from_json(one, source));
  return planes;
}

RigidTransform transform_from_json(const Json& j, const std::string& source) {
  if (!j.is_object() || !j.contains("rotation") || !j.contains("translation"))
    throw InputError(source, "a transform needs 'rotation' (3×3) and 'translation'");
  RigidTransform t;
  const Json& rows = j["rotation"];
  if (!rows.is_array() || rows.size() != 3)
    throw InputError(source, "'rotation' must be 3 rows of 3 numbers");
  for (int r = 0; r < 3; ++r)
    t.rotation.row(r) = vector_from_json(rows[r], source, "rotation").transpose();
  if ((t.rotation * t.rotation.transpose() - Eigen::Matrix3d::Identity()).norm() > 1e-4 ||
      t.rotation.determinant() < 0)
    throw InputError(source, "'rotation' is not a rotation matrix");
  t.translation = vector_from_json(j["translation"], source, "translation");
  return t;
}

Landmarks landmarks_from_json(const Json& j, const std::string& source) {
  if (!j.is_object()) throw InputError(source, "landmarks must be a JSON object");
  Landmarks lm;
  if (j.contains("nasion")) lm.nasion = vector_from_json(j["nasion"], source, "nasion");
  if (j.contains("orbit_left"))
    lm.orbit_left = vector_from_json(j["orbit_left"], source, "orbit_left");
  if (j.contains("orbit_right"))
    lm.orbit_right = vector_from_json(j["orbit_right"], source, "orbit_right");
  if (j.contains("midline")) {
    if (!j["midline"].is_array()) throw InputError(source, "'midline' must be a list of points");
    for (const auto& p : j["midline"]) lm.midline.push_back(vector_from_json(p, source, "midline"));
  }
  if (!lm.has_required())
    throw InputError(source, "landmarks need 'nasion', 'orbit_left' and 'orbit_right'");
  if ((*lm.orbit_left - *lm.orbit_right).norm() < 1.0)
    throw InputError(source, "'orbit_left' and 'orbit_right' are less than 1 mm apart");
  return lm;
}

namespace {
// A number or text field of a recorded result, named in errors.
double result_number(const Json& j, const char* key, const std::string& source) {
  if (!j.contains(key) || !j[key].is_number())
    throw InputError(source, std::string("'") + key + "' must be a number");
  return j[key].get<double>();
}
std::string result_text(const Json& j, const char* key, const std::string& source) {
  if (!j.contains(key) || !j[key].is_string())
    throw InputError(source, std::string("'") + key + "' must be text");
  return j[key].get<std::string>();
}
// PlaneFit::Status and RegisterResult::Status alike (kStatusNames).
template <class Status>
Status status_from_json(const Json& j, const std::string& source) {
  const std::string status = result_text(j, "status", source);
  for (int k = 0; k < 3; ++k)
    if (status == kStatusNames[k]) return static_cast<Status>(k);
  throw InputError(source, "unknown status \"" + status + "\"");
}
}  // namespace

RegisterResult register_result_from_json(const Json& j, const std::string& source) {
  if (!j.is_object()) throw InputError(source, "a registration must be a JSON object");
  RegisterResult r;
  r.transform = transform_from_json(j, source);
  r.rms_mm = result_number(j, "rms_mm", source);
  r.inlier_fraction = result_number(j, "inlier_fraction", source);
  r.iterations = static_cast<int>(result_number(j, "iterations", source));
  r.status = status_from_json<RegisterResult::Status>(j, source);
  r.message = result_text(j, "message", source);
  r.seconds = result_number(j, "seconds", source);
  return r;
}

PlaneFit plane_fit_from_json(const Json& j, const std::string& source) {
  if (!j.is_object()) throw InputError(source, "a plane fit must be a JSON object");
  for (const char* key : {"normal", "initial"})
    if (!j.contains(key)) throw InputError(source, std::string("plane fit has no '") + key + "'");
  PlaneFit fit;
  // As recorded, not normalised again: a replay gives the same plane to the bit.
  fit.plane.normal = vector_from_json(j["normal"], source, "normal");
  if (fit.plane.normal.norm() < 0.5)
    throw InputError(source, "plane 'normal' is not a unit vector");
  fit.plane.offset = result_number(j, "offset_mm", source);
  fit.initial = plane_from_json(j["initial"], source);
  fit.symmetry_rms_mm = result_number(j, "symmetry_rms_mm", source);
  fit.inlier_fraction = result_number(j, "inlier_fraction", source);
  fit.iterations = static_cast<int>(result_number(j, "iterations", source));
  fit.solver_iterations = static_cast<int>(result_number(j, "solver_iterations", source));
  fit.status = status_from_json<PlaneFit::Status>(j, source);
  fit.message = result_text(j, "message", source);
  fit.termination = result_text(j, "termination", source);
  fit.initial_method = result_text(j, "initial_method", source);
  fit.seconds = result_number(j, "seconds", source);
  return fit;
}

Json read_json_file(const std::string& path) {
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) throw InputError(path, "file not found");
  if (std::filesystem::is_directory(path, ec)) throw InputError(path, "is a folder, not a file");
  std::ifstream in(path);
  if (!in) throw InputError(path, std::string("cannot open file: ") + std::strerror(errno));
  std::stringstream buffer;
  buffer << in.rdbuf();
  const std::string text = buffer.str();
  if (text.find_first_not_of(" \t\r\n") == std::string::npos)
    throw InputError(path, "file is empty");
  try {
    return Json::parse(text);
  } catch (const nlohmann::json::exception& e) {  // a syntax error, or a number out of range
    std::string what = e.what();
    const size_t colon = what.find("] ");
    throw InputError(path, "not valid JSON (" +
                               (colon == std::string::npos ? what : what.substr(colon + 2)) + ")");
  }
}

void write_json_file(const Json& j, const std::string& path) {
  write_file_atomically(path, j.dump(2) + "\n");
}

Landmarks read_landmarks_file(const std::string& path) {
  const Json j = read_json_file(path);
  return is_markups_path(path) ? landmarks_from_markups(j, path) : landmarks_from_json(j, path);
}

void write_landmarks_file(const Landmarks& landmarks, const std::string& path) {
  write_json_file(is_markups_path(path) ? landmarks_to_markups(landmarks) : to_json(landmarks),
                  path);
}

Plane read_plane_file(const std::string& path) {
  return plane_from_json(read_json_file(path), path);
}

}  // namespace cranioplan
