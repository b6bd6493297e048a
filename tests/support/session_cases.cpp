#include "support/session_cases.h"

#include <gtest/gtest.h>

#include "cranioplan/algorithms/io/write_mesh.h"
#include "cranioplan/algorithms/quality/inject_defect.h"
#include "cranioplan/sessions/autoplan_session.h"
#include "cranioplan/sessions/sha256.h"
#include "support/synthetic.h"
#include "support/test_files.h"

namespace cranioplan::test {

std::string scratch_path(const std::string& name) {
  static TempDir dir;
  return dir.path(name);
}

const PlannedCase& planned_defect_case() {
  static const PlannedCase c = [] {
    PlannedCase p;
    p.session_path = scratch_path("auto.json");
    p.implant_path = scratch_path("auto_implant.stl");
    AutoplanSession a = autoplan_session(defect_skull_stl(), Landmarks{}, AutoplanParams{},
                                         p.implant_path, SessionInfo{"synthetic", "expert", ""});
    EXPECT_TRUE(a.planned()) << a.message;
    a.session.save(p.session_path);
    p.implant_sha = sha256_file(p.implant_path);
    return p;
  }();
  return c;
}

const std::string& small_skull_stl() {
  static const std::string path = [] {
    const std::string p = scratch_path("small_skull.stl");
    const SkullMesh head = make_symmetric_head(4);
    write_mesh(cut_hole(head, head_surface_point(Eigen::Vector3d(0.7, 0.1, 0.7).normalized()), 25),
               p);
    return p;
  }();
  return path;
}

namespace {
const InjectDefectResult& defect_case() {
  static const InjectDefectResult d = [] {
    InjectDefectParams p;
    p.center = head_surface_point(Eigen::Vector3d(0.75, 0.2, 0.6).normalized()) * 0.965;
    p.size_mm = 45;
    p.voxel_mm = 0.8;
    return inject_defect(make_thick_head(0.93, 0.8), p);
  }();
  return d;
}
}  // namespace

const std::string& defect_skull_stl() {
  static const std::string path = [] {
    const std::string p = scratch_path("defect_skull.stl");
    write_mesh(defect_case().defective, p);
    return p;
  }();
  return path;
}

const std::string& defect_implant_stl() {
  static const std::string path = [] {
    const std::string p = scratch_path("defect_implant.stl");
    write_mesh(defect_case().implant, p);
    return p;
  }();
  return path;
}

Json fingerprint(const PlanState& s) {
  Json j;
  j["skull"] = s.skull ? s.skull->sha256 : "";
  j["landmarks"] = to_json(s.landmarks);
  j["plane"] = s.plane ? to_json(*s.plane) : Json(nullptr);
  j["mirror"] = s.mirrored ? to_json(s.mirror_transform()) : Json(nullptr);
  j["registered"] = s.registration ? s.registration->rms_mm : -1.0;
  j["clip"] = s.clip_plane ? to_json(*s.clip_plane) : Json(nullptr);
  Json markers = Json::array();
  for (const auto& m : s.markers)
    markers.push_back(
        {m.id, static_cast<int>(m.type), to_json(m.position), static_cast<int>(m.surface)});
  j["markers"] = markers;
  j["next_marker_id"] = s.next_marker_id;
  j["implant"] = s.implant ? s.implant->stl_sha256() : "";
  Json exports = Json::array();
  for (const auto& e : s.exports) exports.push_back({e.path, e.replayed_sha256});
  j["exports"] = exports;
  j["acknowledged"] = s.acknowledged;
  j["current_step"] = s.current_step;
  j["notes"] = s.notes;
  return j;
}

std::optional<size_t> first_command(const Session& session, CommandType type) {
  const std::vector<Command> done = session.effective_commands();
  for (size_t i = 0; i < done.size(); ++i)
    if (done[i].type == type) return i;
  return std::nullopt;
}

void push_ok(Session& session, Command command) {
  const std::string what = describe(command);
  const PushResult r = session.push(std::move(command));
  ASSERT_TRUE(r.accepted) << what << ": " << r.message;
}

std::string validate_session_schema(const std::string& path) {
  return validate_json_schema(path,
                              std::string(CRANIOPLAN_SOURCE_DIR) + "/docs/session.schema.json");
}

std::string validate_json_schema(const std::string& path, const std::string& schema) {
  std::string out;
  if (run_command("python3 -c 'import jsonschema'") != 0) return "skip";
  const std::string cmd =
      "python3 -c 'import json,sys,jsonschema; "
      "jsonschema.validate(json.load(open(sys.argv[2])), "
      "json.load(open(sys.argv[1]))); print(\"valid\")' '" +
      schema + "' '" + path + "' 2>&1";
  run_command(cmd, &out);
  return out.find("valid") == 0 ? std::string() : out;
}

}  // namespace cranioplan::test
