#include "cranioplan/sessions/session.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <random>

#include "cranioplan/algorithms/io/extract_bone_surface.h"
#include "cranioplan/algorithms/io/mesh_report.h"
#include "cranioplan/algorithms/io/write_3mf.h"
#include "cranioplan/algorithms/io/write_mesh.h"
#include "cranioplan/model/error.h"
#include "cranioplan/sessions/audit.h"
#include "cranioplan/sessions/marker_files.h"
#include "cranioplan/sessions/plan_files.h"
#include "cranioplan/sessions/session_error.h"
#include "support/session_cases.h"
#include "support/synthetic.h"
#include "support/test_files.h"

namespace cranioplan {
namespace {

namespace fs = std::filesystem;
using test::fingerprint;
using test::push_ok;

// A session on the small head brought to step 5 (markers unlocked).
Session session_at_markers() {
  Session s(SessionInfo{"small", "tester", ""});
  push_ok(s, commands::load_skull(test::small_skull_stl()));
  const Landmarks lm = test::head_landmarks();
  push_ok(s, commands::set_landmark("nasion", *lm.nasion));
  push_ok(s, commands::set_landmark("orbit_left", *lm.orbit_left));
  push_ok(s, commands::set_landmark("orbit_right", *lm.orbit_right));
  PlaneFitParams fit;
  fit.sample_count = 1000;
  push_ok(s, commands::fit_plane(fit));
  push_ok(s, commands::mirror());
  RegisterParams reg;
  reg.sample_count = 1000;
  push_ok(s, commands::register_mirror(reg));
  push_ok(s, commands::complete_step(4));
  return s;
}

Eigen::Vector3d on_head(double x, double y, double z) {
  return test::head_surface_point(Eigen::Vector3d(x, y, z).normalized());
}

// Three outer edge markers around the hole: step 5 done, surface markers unlocked.
void add_rim(Session& s) {
  for (double a : {0.0, 2.1, 4.2})
    push_ok(s, commands::add_marker(MarkerType::OuterEdge, on_head(0.7 + 0.2 * std::cos(a),
                                                                   0.1 + 0.2 * std::sin(a), 0.7)));
}

// Three outer surface markers inside the rim, at height `z` of the head's direction.
void add_surface_markers(Session& s, double z) {
  for (double a : {0.5, 2.6, 4.7})
    push_ok(s, commands::add_marker(MarkerType::OuterSurface,
                                    on_head(0.7 + 0.1 * std::cos(a), 0.1 + 0.1 * std::sin(a), z)));
}

std::string expect_session_error(const std::string& path) {
  try {
    Session::open(path);
  } catch (const InputError& e) {
    return e.what();
  }
  ADD_FAILURE() << "no error for " << path;
  return {};
}

TEST(StepLock, LaterStepsAreRefusedWithWhatIsMissing) {
  Session s;
  PushResult r = s.push(commands::add_marker(MarkerType::OuterEdge, {0, 0, 0}));
  EXPECT_FALSE(r.accepted);
  EXPECT_NE(r.message.find("step 5 (Edge markers) is locked: step 1 (Load skull) is not done"),
            std::string::npos)
      << r.message;
  push_ok(s, commands::load_skull(test::small_skull_stl()));
  r = s.push(commands::mirror());
  EXPECT_FALSE(r.accepted);
  EXPECT_NE(r.message.find("step 2"), std::string::npos) << r.message;
  EXPECT_TRUE(s.push(commands::note("any step")).accepted);
  EXPECT_FALSE(s.push(commands::complete_step(2)).accepted);
  EXPECT_FALSE(s.push(commands::export_implant(test::scratch_path("x.stl"))).accepted);
  EXPECT_FALSE(fs::exists(test::scratch_path("x.stl"))) << "a refused export wrote a file";
  EXPECT_EQ(s.effective_commands().size(), 2u) << "refused commands are not recorded";

  Session m = session_at_markers();
  // Step 6 needs step 5: three outer edge markers.
  r = m.push(commands::add_marker(MarkerType::OuterSurface, on_head(0.7, 0.1, 0.7)));
  EXPECT_FALSE(r.accepted);
  EXPECT_NE(r.message.find("outer edge markers (0 so far)"), std::string::npos) << r.message;
  add_rim(m);
  EXPECT_TRUE(
      m.push(commands::add_marker(MarkerType::OuterSurface, on_head(0.7, 0.1, 0.7))).accepted);
  // Two inner edge markers are neither none nor three.
  push_ok(m, commands::add_marker(MarkerType::InnerEdge, on_head(0.6, 0.1, 0.7)));
  std::string missing;
  EXPECT_FALSE(step_complete(m.state(), 5, &missing));
  EXPECT_NE(missing.find("inner edge markers: 1 placed"), std::string::npos) << missing;
}

// Opening a plan says how far its replay is: each command before it is replayed, then the end.
TEST(Session, OpeningReportsTheCommandsReplayed) {
  std::vector<std::pair<size_t, size_t>> calls;
  OpenOptions options;
  options.progress = [&calls](size_t done, size_t total) { calls.emplace_back(done, total); };
  const Session s = Session::open(test::planned_defect_case().session_path, options);
  const size_t n = s.index();
  ASSERT_GT(n, 3u);
  ASSERT_EQ(calls.size(), n + 1);
  for (size_t k = 0; k <= n; ++k) EXPECT_EQ(calls[k], std::make_pair(k, n));
}

TEST(Session, AVersionOneBuildIsAppliedWithoutFitting) {
  Session s = session_at_markers();
  add_rim(s);
  add_surface_markers(s, 0.7);
  Json v1 = to_json(commands::build_implant());
  v1["version"] = 1;
  v1["params"]["params"].erase("fit_to_bone_mm");
  const PushResult r = s.push(command_from_json(v1, "old plan"));
  ASSERT_TRUE(r.accepted) << r.message;
  ASSERT_TRUE(s.state().implant_params);
  EXPECT_EQ(s.state().implant_params->fit_to_bone_mm, 0.0);
}

// The first command of `type` in the session has `version` and records `expected` as its
// "result".
void expect_recorded_result(const Session& s, CommandType type, int version, const Json& expected) {
  const auto at = test::first_command(s, type);
  ASSERT_TRUE(at) << type_tag(type);
  const Command c = s.effective_commands()[*at];
  EXPECT_EQ(c.version, version);
  ASSERT_TRUE(c.params.contains("result")) << type_tag(type);
  EXPECT_EQ(c.params["result"], expected);
}

// The plane fit is recorded in its command (fit_plane 2) and a replay applies the recorded
// plane; a version-1 fit_plane (before the coarse start) is still read and fitted.
TEST(Session, APlaneFitIsRecordedAndReplayedAsRecorded) {
  Session s = session_at_markers();
  expect_recorded_result(s, CommandType::FitPlane, 2, to_json(*s.state().plane_fit));

  Session t(SessionInfo{"small", "tester", ""});
  push_ok(t, commands::load_skull(test::small_skull_stl()));
  Command recorded = commands::fit_plane();
  PlaneFit chosen;
  chosen.status = PlaneFit::Status::Converged;
  chosen.plane = Plane{Eigen::Vector3d(0.6, 0.8, 0.0), 3.25};  // not what the fit would give
  chosen.initial = chosen.plane;
  chosen.initial_method = "automatic";
  chosen.message = "converged";
  recorded.params["result"] = to_json(chosen);
  push_ok(t, recorded);
  ASSERT_TRUE(t.state().plane);
  EXPECT_EQ(t.state().plane->normal, Eigen::Vector3d(0.6, 0.8, 0.0));
  EXPECT_EQ(t.state().plane->offset, 3.25);

  Json v1 = to_json(commands::fit_plane());
  v1["version"] = 1;
  v1["params"]["params"].erase("coarse_iterations");
  v1["params"]["params"].erase("coarse_robust_scale_mm");
  Session u(SessionInfo{"small", "tester", ""});
  push_ok(u, commands::load_skull(test::small_skull_stl()));
  push_ok(u, command_from_json(v1, "old plan"));
  EXPECT_TRUE(u.state().plane);
  EXPECT_FALSE(u.effective_commands().back().params.contains("result"))
      << "a version-1 command is kept as recorded";
}

// The registration is recorded in the register command (version 2), and in the command that
// changed the plane when the mirror was registered again; a replay applies what is recorded.
TEST(Session, RegistrationsAreRecordedAndReplayedAsRecorded) {
  Session s = session_at_markers();
  expect_recorded_result(s, CommandType::Register, 2, to_json(*s.state().registration));

  // Turning the plane registers the mirror again: recorded in the adjust_plane command.
  push_ok(s, commands::adjust_plane({0, 0, 1}, 1.0, 0.5));
  const Command adjust = s.effective_commands().back();
  EXPECT_EQ(adjust.version, 2);
  ASSERT_TRUE(adjust.params.contains("registration"));
  EXPECT_EQ(adjust.params["registration"], to_json(*s.state().registration));
  const std::string path = test::scratch_path("registered.json");
  s.save(path);
  EXPECT_EQ(fingerprint(Session::open(path).state()), fingerprint(s.state()));
  EXPECT_EQ(test::validate_session_schema(path), "");

  // What is recorded is what is applied: a registration ICP would not give, as it is.
  Session t = session_at_markers();
  Command recorded = commands::register_mirror();
  RegisterResult chosen;
  chosen.status = RegisterResult::Status::Converged;
  chosen.transform = RigidTransform::from_axis_angle({0, 1, 0}, 2.5, {1.0, -0.5, 0.25});
  chosen.rms_mm = 0.3;
  chosen.message = "converged";
  recorded.params["result"] = to_json(chosen);
  push_ok(t, recorded);
  ASSERT_TRUE(t.state().registration);
  EXPECT_EQ(t.state().registration->transform.rotation, chosen.transform.rotation);
  EXPECT_EQ(t.state().registration->transform.translation, chosen.transform.translation);
}

// A proposal is recorded in its command when it is first done, and a replay applies the
// recorded markers: a plan reopened with a later planner stays the plan the surgeon edited.
TEST(Session, AProposalIsRecordedAndReplayedAsRecorded) {
  // The small head's hole is too small to propose for: the failure is what is recorded.
  Session s = session_at_markers();
  push_ok(s, commands::propose_markers());
  const Json result = s.effective_commands().back().params.value("result", Json());
  EXPECT_EQ(result["proposed"], false);
  EXPECT_EQ(result["message"], s.state().message);
  EXPECT_NE(s.state().message.find("no markers proposed"), std::string::npos);
  const std::string path = test::scratch_path("proposed.json");
  s.save(path);
  EXPECT_EQ(fingerprint(Session::open(path).state()), fingerprint(s.state()));
  EXPECT_EQ(test::validate_session_schema(path), "");

  // What is recorded is what is applied: markers the planner would never propose, as they are.
  Session t = session_at_markers();
  push_ok(t, commands::add_marker(MarkerType::OuterEdge, on_head(0.7, 0.3, 0.7)));
  Command recorded = commands::propose_markers();
  Json markers = Json::array();
  for (int i = 0; i < 3; ++i)
    markers.push_back(
        to_json(Marker{40 + i, MarkerType::OuterEdge,
                       on_head(0.7 + 0.2 * std::cos(2.1 * i), 0.1 + 0.2 * std::sin(2.1 * i), 0.7),
                       MarkerSurface::Original}));
  recorded.params["result"] = {{"proposed", true},
                               {"markers", markers},
                               {"defect_center", to_json(Eigen::Vector3d(1, 2, 3))},
                               {"message", "3 markers recorded"}};
  push_ok(t, recorded);
  ASSERT_EQ(t.state().markers.size(), 3u);
  for (int i = 0; i < 3; ++i) {
    EXPECT_EQ(t.state().markers[i].id, 40 + i);
    EXPECT_EQ(to_json(t.state().markers[i].position), markers[i]["position"]);
  }
  EXPECT_EQ(t.state().next_marker_id, 43);
  EXPECT_EQ(*t.state().defect_center, Eigen::Vector3d(1, 2, 3));
  EXPECT_EQ(t.state().proposal_message, "3 markers recorded");
  EXPECT_EQ(t.effective_commands().back().params["result"], recorded.params["result"])
      << "a recorded result is kept, not recorded again";
  EXPECT_TRUE(t.state().unseen_rim.empty()) << "an older recorded result has none";

  // The rim's unseen stretches are applied as recorded, for the view to draw;
  // a malformed list is named.
  Command with_stretch = recorded;
  with_stretch.params["result"]["unseen_rim"] = {
      {{"from", to_json(Eigen::Vector3d(1, 2, 3))}, {"to", to_json(Eigen::Vector3d(4, 5, 6))}}};
  Session u = session_at_markers();
  push_ok(u, with_stretch);
  ASSERT_EQ(u.state().unseen_rim.size(), 1u);
  EXPECT_EQ(u.state().unseen_rim[0].from, Eigen::Vector3d(1, 2, 3));
  EXPECT_EQ(u.state().unseen_rim[0].to, Eigen::Vector3d(4, 5, 6));
  Command bad_stretch = recorded;
  bad_stretch.params["result"]["unseen_rim"] = 7;
  try {
    u.push(bad_stretch);
    ADD_FAILURE() << "a malformed unseen_rim was applied";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("unseen_rim"), std::string::npos) << e.what();
  }

  // A recorded failure leaves the markers as they were and says why.
  Command failed = commands::propose_markers();
  failed.params["result"] = {{"proposed", false},
                             {"markers", Json::array()},
                             {"defect_center", nullptr},
                             {"message", "no markers proposed: no opening found"}};
  push_ok(t, failed);
  EXPECT_EQ(t.state().markers.size(), 3u);
  EXPECT_EQ(t.state().message, "no markers proposed: no opening found");

  // A malformed recorded result is named, not a crash.
  Command broken = commands::propose_markers();
  broken.params["result"] = {{"proposed", true}, {"markers", 7}};
  try {
    t.push(broken);
    ADD_FAILURE() << "a malformed result was applied";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("result"), std::string::npos) << e.what();
  }
}

// A search run for a command before it is pushed (autoplan_session runs the plan's stages so)
// counts in the command's time, which the audit shows; a command without one is timed alone.
TEST(Session, ASearchRunBeforeACommandCountsInItsTime) {
  Session s(SessionInfo{"small", "tester", ""});
  push_ok(s, commands::load_skull(test::small_skull_stl()));
  Command note = commands::note("searched for a while");
  note.meta.duration_ms = 1234.0;
  push_ok(s, note);
  push_ok(s, commands::note("not searched"));
  const std::vector<Command>& done = s.effective_commands();
  ASSERT_EQ(done.size(), 3u);
  EXPECT_GE(done[1].meta.duration_ms, 1234.0);
  EXPECT_LT(done[2].meta.duration_ms, 1234.0);
}

TEST(Session, MarkersSnapToTheirSurfaceAndKeepStableIds) {
  Session s = session_at_markers();
  push_ok(s, commands::add_marker(MarkerType::OuterEdge, on_head(0.6, 0.0, 0.8) * 1.02));
  add_rim(s);
  const Marker first = s.state().markers[0];
  EXPECT_EQ(first.id, 1);
  EXPECT_LT(s.state().skull->surface->locator.closest(first.position).distance, 1e-6);
  push_ok(s, commands::delete_marker(1));
  push_ok(s, commands::add_marker(MarkerType::OuterEdge, on_head(0.6, 0.0, 0.8)));
  EXPECT_EQ(s.state().markers.back().id, 5) << "ids are never reused";
  push_ok(s, commands::retype_marker(5, MarkerType::OuterSurface));
  EXPECT_EQ(s.state().markers.back().surface, MarkerSurface::Mirrored);
  EXPECT_LT(s.state().mirrored->locator.closest(s.state().markers.back().position).distance, 1e-6);
  EXPECT_FALSE(s.push(commands::move_marker(42, {0, 0, 0})).accepted);
}

TEST(Session, DragsOfOneMarkerMergeIntoOneCommand) {
  Session s = session_at_markers();
  push_ok(s, commands::add_marker(MarkerType::OuterEdge, on_head(0.6, 0.0, 0.8)));
  const Json before = fingerprint(s.state());
  const size_t n = s.effective_commands().size();
  for (int i = 1; i <= 5; ++i) {
    const PushResult r = s.push(commands::move_marker(1, on_head(0.6, 0.02 * i, 0.8)));
    EXPECT_TRUE(r.accepted);
    EXPECT_EQ(r.merged, i > 1);
  }
  EXPECT_EQ(s.effective_commands().size(), n + 1);
  EXPECT_EQ(s.undo_text(), "Undo Move marker 1");
  s.undo();
  EXPECT_EQ(fingerprint(s.state()), before);
  int merges = 0;
  for (const auto& e : s.journal()) merges += e.event == "merge";
  EXPECT_EQ(merges, 4);
}

TEST(Session, PushAfterUndoDropsTheRedoBranchButTheJournalKeepsIt) {
  Session s = session_at_markers();
  push_ok(s, commands::note("a"));
  push_ok(s, commands::note("b"));
  ASSERT_TRUE(s.undo());
  EXPECT_EQ(s.redo_text(), "Redo Note: b");
  push_ok(s, commands::note("c"));
  EXPECT_FALSE(s.can_redo());
  ASSERT_EQ(s.state().notes.size(), 2u);
  EXPECT_EQ(s.state().notes[1], "c");
  const std::string path = test::scratch_path("redo.json");
  s.save(path);
  const auto rows = audit_rows(read_session_document(path));
  int undone = 0;
  for (const auto& r : rows) undone += r.undone;
  EXPECT_EQ(undone, 1) << "note b was done, undone, then dropped";
}

// The random walk: 1,000 do/undo/redo operations; the final state equals a fresh replay
// of the effective list, and undoing everything gives the initial state back.
TEST(Session, RandomWalkEqualsFreshReplay) {
  Session s = session_at_markers();
  add_rim(s);
  s.set_cache_limit(40);            // also exercises recomputing evicted states
  const size_t prefix = s.index();  // the walk stays above the loaded, registered skull
  const Json initial = fingerprint(PlanState{});
  std::mt19937 rng(12345);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  auto random_point = [&] {
    return on_head(0.7 + 0.25 * unit(rng), 0.1 + 0.25 * unit(rng), 0.7 + 0.2 * unit(rng));
  };
  int accepted = 0;
  for (int op = 0; op < 1000; ++op) {
    const int kind = static_cast<int>(rng() % 12);
    const auto& markers = s.state().markers;
    const int some_id = markers.empty() ? 1 : markers[rng() % markers.size()].id;
    PushResult r;
    switch (kind) {
      case 0:
      case 1:
        if (s.index() > prefix) s.undo();
        continue;
      case 2:
        s.redo();
        continue;
      case 3:
      case 4:
        r = s.push(commands::add_marker(static_cast<MarkerType>(rng() % 4), random_point()));
        break;
      case 5:
      case 6:
        r = s.push(commands::move_marker(some_id, random_point()));
        break;
      case 7:
        r = s.push(commands::delete_marker(some_id));
        break;
      case 8:
        r = s.push(commands::retype_marker(some_id, static_cast<MarkerType>(rng() % 4)));
        break;
      case 9:
        r = s.push(commands::set_clip_plane(Plane{Eigen::Vector3d::UnitZ(), 10 * unit(rng)}));
        break;
      case 10:
        r = s.push(commands::note("n" + std::to_string(op)));
        break;
      default:
        if (rng() % 25 == 0) {
          r = s.push(commands::move_mirrored({0, 0, 1}, unit(rng), {0, 0, 0}, {unit(rng), 0, 0}));
        } else {
          s.set_index(prefix + rng() % (s.stack().size() - prefix + 1));
          continue;
        }
    }
    accepted += r.accepted;
  }
  EXPECT_GT(accepted, 200);
  const std::string path = test::scratch_path("walk.json");
  s.save(path);
  const Session replayed = Session::open(path);
  EXPECT_EQ(fingerprint(replayed.state()), fingerprint(s.state()));
  EXPECT_EQ(replayed.effective_commands().size(), s.effective_commands().size());
  EXPECT_EQ(replayed.stack().size(), s.stack().size()) << "the redo branch is kept";
  s.set_index(0);
  EXPECT_EQ(fingerprint(s.state()), initial);
  EXPECT_EQ(test::validate_session_schema(path), "") << path;
}

// Implants fitted to the bone are large: the cached states keep at most a budget of implant
// triangles, and states evicted for it are recomputed exactly on undo.
TEST(Session, CachedImplantsStayWithinTheirTriangleBudget) {
  Session s = session_at_markers();
  add_rim(s);
  add_surface_markers(s, 0.72);
  push_ok(s, commands::build_implant());
  ASSERT_TRUE(s.state().implant);
  const size_t one = s.state().implant->result().mesh.n_faces();
  const size_t budget = 3 * one;
  s.set_cache_implant_triangles(budget);
  const int id = s.state().markers.back().id;
  std::vector<Json> states;
  for (int k = 0; k < 12; ++k) {
    push_ok(s, commands::note("separates the drags"));  // one drag each, not merged
    push_ok(s, commands::move_marker(id, on_head(0.7 + 0.01 * k, 0.1, 0.72)));
    ASSERT_TRUE(s.state().implant);
    states.push_back(fingerprint(s.state()));
    EXPECT_LE(s.cached_implant_triangles(), budget) << "after move " << k;
  }
  for (int k = 10; k >= 0; --k) {
    ASSERT_TRUE(s.undo());  // the note
    ASSERT_TRUE(s.undo());  // the move
    EXPECT_EQ(fingerprint(s.state()), states[k]) << "state after move " << k;
  }
}

TEST(Session, ChangingThePlaneRecomputesTheMirrorAndMarksLaterStepsStale) {
  Session s = session_at_markers();
  const Json mirror_before = fingerprint(s.state())["mirror"];
  add_rim(s);
  push_ok(s, commands::add_marker(MarkerType::OuterSurface, on_head(0.7, 0.1, 0.7)));
  push_ok(s, commands::adjust_plane({0, 0, 1}, 2.0, 0.0));
  EXPECT_TRUE(s.state().stale.count(3));
  EXPECT_TRUE(s.state().stale.count(4));
  EXPECT_TRUE(s.state().stale.count(6));
  EXPECT_FALSE(step_complete(s.state(), 4)) << "inspect again after the plane moved";
  EXPECT_NE(fingerprint(s.state())["mirror"], mirror_before) << "registered again";
  s.undo();
  EXPECT_TRUE(step_complete(s.state(), 4));
}

TEST(SessionFile, SavedSessionsFollowTheSchemaAndReopen) {
  Session s = session_at_markers();
  push_ok(s, commands::note("für den Chirurgen"));
  const std::string path = test::scratch_path("schema.json");
  s.save(path);
  EXPECT_TRUE(s.is_clean());
  EXPECT_EQ(test::validate_session_schema(path), "");
  const Session back = Session::open(path);
  EXPECT_TRUE(back.is_clean());
  EXPECT_EQ(fingerprint(back.state()), fingerprint(s.state()));
  EXPECT_EQ(back.journal().size(), s.journal().size());
}

TEST(SessionFile, VersionOneIsUpgraded) {
  Session s = session_at_markers();
  const std::string path = test::scratch_path("v2.json");
  s.save(path);
  Json v1 = read_json_file(path);
  v1["schema_version"] = 1;
  v1["app"] = "cranioplan 0.1.0";
  v1["case"] = v1["case_id"];
  for (const char* k : {"app_version", "case_id", "inputs", "redo_commands"}) v1.erase(k);
  const std::string old_path = test::scratch_path("v1.json");
  write_json_file(v1, old_path);
  const Session back = Session::open(old_path);
  EXPECT_EQ(back.header().info.case_id, "small");
  EXPECT_EQ(fingerprint(back.state()), fingerprint(s.state()));
}

TEST(SessionFile, BadFilesGetClearErrors) {
  Session s = session_at_markers();
  const std::string good = test::scratch_path("good.json");
  s.save(good);
  const Json doc = read_json_file(good);
  auto variant = [&](const std::string& name, const Json& j) {
    const std::string p = test::scratch_path(name);
    write_json_file(j, p);
    return p;
  };
  auto contains = [](const std::string& text, const std::string& part) {
    return text.find(part) != std::string::npos;
  };

  const std::string not_json = test::scratch_path("not.json");
  test::write_bytes(not_json, "{\"schema_version\": 2, \"commands\": [");
  EXPECT_TRUE(contains(expect_session_error(not_json), "not.json"));

  Json future = doc;
  future["schema_version"] = 9;
  EXPECT_TRUE(contains(expect_session_error(variant("future.json", future)),
                       "unknown session schema version 9"));

  Json unknown = doc;
  unknown["commands"][2]["type"] = "paint_skull";
  const std::string unknown_msg = expect_session_error(variant("unknown.json", unknown));
  EXPECT_TRUE(contains(unknown_msg, "commands[2]")) << unknown_msg;
  EXPECT_TRUE(contains(unknown_msg, "unknown command type \"paint_skull\"")) << unknown_msg;

  Json missing = doc;
  missing["commands"][4]["params"].erase("params");
  EXPECT_TRUE(contains(expect_session_error(variant("missing.json", missing)),
                       "missing parameter 'params'"));

  Json tampered = doc;
  tampered["journal"][5]["time"] = "2020-01-01T00:00:00.000Z";
  EXPECT_TRUE(contains(expect_session_error(variant("chain.json", tampered)),
                       "the hash chain breaks at journal entry 6"));
}

TEST(SessionFile, MissingOrChangedSkullIsNamed) {
  const std::string skull = test::scratch_path("own_skull.stl");
  fs::copy_file(test::small_skull_stl(), skull, fs::copy_options::overwrite_existing);
  Session s(SessionInfo{"own", "tester", ""});
  push_ok(s, commands::load_skull(skull));
  const std::string path = test::scratch_path("own.json");
  s.save(path);
  std::string bytes = test::read_bytes(skull);
  bytes[100] ^= 1;
  test::write_bytes(skull, bytes);
  const std::string changed = expect_session_error(path);
  EXPECT_NE(changed.find("the skull file changed since this plan was made"), std::string::npos)
      << changed;
  EXPECT_NE(changed.find("own_skull.stl"), std::string::npos);
  fs::remove(skull);
  const std::string missing = expect_session_error(path);
  EXPECT_NE(missing.find("the skull file of this plan is missing"), std::string::npos) << missing;
}

// A plan made from a mesh is given its CT: the CT's bone surface must lie on the skull. The
// check is recorded, the CT is an input of the plan (verify checks its bytes), and a CT of
// another frame is refused.
TEST(SessionFile, ACtAttachedToAMeshPlanIsCheckedRecordedAndVerified) {
  test::TempDir dir;
  const Volume ct = test::make_ball_volume(Eigen::Vector3d(0, 0, 60), 70.0, 80, 2.0, true);
  test::write_nrrd(ct, dir.path("ct.nrrd"), true);
  write_mesh(extract_bone_surface(ct).mesh, dir.path("skull.stl"));
  Volume moved = ct;
  moved.origin.z() += 25.0;
  test::write_nrrd(moved, dir.path("other.nrrd"), true);

  Session s;
  push_ok(s, commands::load_skull(dir.path("skull.stl")));
  const PushResult wrong = s.push(commands::attach_ct(dir.path("other.nrrd")));
  EXPECT_FALSE(wrong.accepted);
  EXPECT_NE(wrong.message.find("not this skull's CT, or not in its frame"), std::string::npos)
      << wrong.message;
  EXPECT_FALSE(s.state().ct);
  push_ok(s, commands::attach_ct(dir.path("ct.nrrd")));
  ASSERT_TRUE(s.state().ct);
  EXPECT_LT(s.state().ct->median_mm, 0.1);
  EXPECT_EQ(s.state().current_step, 2) << "attaching a CT is no step of its own";
  const Command attach = s.effective_commands().back();
  EXPECT_TRUE(attach.params.contains("result")) << "the check is recorded";
  EXPECT_EQ(attach.params["sha256"].get<std::string>().size(), 64u);

  s.save(dir.path("plan.json"));
  EXPECT_EQ(test::validate_session_schema(dir.path("plan.json")), "");
  const Json saved = read_json_file(dir.path("plan.json"));
  ASSERT_EQ(saved["inputs"].size(), 2u);
  EXPECT_EQ(saved["inputs"][1]["role"], "ct");
  const Session reopened = Session::open(dir.path("plan.json"));
  ASSERT_TRUE(reopened.state().ct);
  EXPECT_EQ(reopened.state().ct->message, s.state().ct->message);
  EXPECT_TRUE(verify_session(dir.path("plan.json")).ok());
  // A changed CT is caught.
  test::write_nrrd(moved, dir.path("ct.nrrd"), true);
  EXPECT_FALSE(verify_session(dir.path("plan.json")).ok());
  // A new skull drops the CT of the old one.
  Session t;
  push_ok(t, commands::load_skull(dir.path("skull.stl")));
  EXPECT_FALSE(t.state().ct);
}

// A 3MF export: the implant and, asked for, a casting mould's two halves in millimetres with
// the plan's hash as it stood (the journal's last entry); verify replays it to the same bytes.
// A mould is only exported in a 3MF.
TEST(SessionFile, A3mfExportWithAMouldReplaysToTheSameBytes) {
  test::TempDir dir;
  Session s = Session::open(test::planned_defect_case().session_path);
  ASSERT_TRUE(s.state().implant);
  const std::string head = s.journal().back().hash;
  MouldParams mould;
  mould.voxel_mm = 0.4;  // a coarser grid: the test's time
  push_ok(s, commands::export_implant(dir.path("plan.3mf"), "", mould));
  const Read3mf package = read_3mf(dir.path("plan.3mf"));
  ASSERT_EQ(package.parts.size(), 3u);
  EXPECT_EQ(package.parts[0].first, "implant");
  EXPECT_EQ(package.parts[1].first, "mould outer");
  EXPECT_EQ(package.parts[2].first, "mould inner");
  EXPECT_EQ(package.metadata.at("Description"),
            plan_description(head, s.state().implant->stl_sha256()));
  for (const auto& [name, mesh] : package.parts) EXPECT_TRUE(report_mesh(mesh).watertight) << name;
  s.save(dir.path("plan.json"));
  EXPECT_TRUE(verify_session(dir.path("plan.json")).ok());
  EXPECT_THROW(commands::export_implant(dir.path("x.stl"), "", mould), InputError);
}

TEST(SessionFile, AutosaveOffersRecoveryOfUnsavedCommands) {
  Session s = session_at_markers();
  s.set_autosave_path(test::scratch_path("unsaved.autosave"));  // as the wizard does
  const std::string path = test::scratch_path("autosaved.json");
  s.save(path);
  EXPECT_EQ(s.autosave_path(), path + ".autosave") << "saving moves the autosave beside the plan";
  EXPECT_FALSE(Session::recovery_info(path).available);
  push_ok(s, commands::note("after save 1"));
  push_ok(s, commands::note("after save 2"));
  s.undo();
  const RecoveryInfo info = Session::recovery_info(path);
  ASSERT_TRUE(info.available) << info.message;
  EXPECT_EQ(info.extra_events, 3);
  OpenOptions recover;
  recover.recover_autosave = true;
  recover.attach_autosave = true;
  const Session recovered = Session::open(path, recover);
  EXPECT_EQ(fingerprint(recovered.state()), fingerprint(s.state()));
  EXPECT_FALSE(recovered.is_clean());
  EXPECT_TRUE(recovered.can_redo());
}

TEST(SessionFile, DeclinedRecoveryKeepsTheUnsavedChangesBesideThePlan) {
  Session s = session_at_markers();
  s.set_autosave_path(test::scratch_path("declined.autosave"));
  const std::string path = test::scratch_path("declined.json");
  s.save(path);
  push_ok(s, commands::note("unsaved"));
  ASSERT_TRUE(Session::recovery_info(path).available);
  OpenOptions keep_saved;
  keep_saved.attach_autosave = true;  // the wizard, answering No
  const Session reopened = Session::open(path, keep_saved);
  EXPECT_TRUE(reopened.state().notes.empty());
  EXPECT_TRUE(fs::exists(path + ".autosave.declined")) << "the declined changes are kept";
  EXPECT_FALSE(Session::recovery_info(path).available);
}

// The crash test: a process that plans and autosaves is killed with SIGKILL at random
// points; every command it reported finished is recovered.
TEST(SessionFile, KillMinusNineLosesNoCompletedCommand) {
  std::mt19937 rng(777);
  const int runs = 30;
  int killed_midway = 0;
  for (int run = 0; run < runs; ++run) {
    const std::string autosave = test::scratch_path("crash" + std::to_string(run) + ".autosave");
    int out_pipe[2];
    ASSERT_EQ(pipe(out_pipe), 0);
    const pid_t pid = fork();
    ASSERT_GE(pid, 0);
    if (pid == 0) {
      dup2(out_pipe[1], 1);
      close(out_pipe[0]);
      execl(CRANIOPLAN_SESSION_WRITER, CRANIOPLAN_SESSION_WRITER, test::small_skull_stl().c_str(),
            autosave.c_str(), "100000", static_cast<char*>(nullptr));
      _exit(127);
    }
    close(out_pipe[1]);
    usleep(50000 + rng() % 400000);
    kill(pid, SIGKILL);
    int status = 0;
    waitpid(pid, &status, 0);
    killed_midway += WIFSIGNALED(status);
    std::string output;
    char buf[4096];
    ssize_t n;
    while ((n = read(out_pipe[0], buf, sizeof(buf))) > 0) output.append(buf, n);
    close(out_pipe[0]);
    int last_done = 0;
    for (size_t at = output.rfind("done "); at != std::string::npos;) {
      last_done = std::atoi(output.c_str() + at + 5);
      break;
    }
    if (last_done == 0) continue;  // killed before the skull was loaded
    const Session recovered = Session::recover(autosave);
    EXPECT_GE(static_cast<int>(recovered.journal().size()), last_done) << "run " << run;
    // The recovered plan is the replay of its own journal.
    const Reconstruction rec = reconstruct(recovered.journal(), autosave);
    EXPECT_EQ(rec.index, recovered.index());
    EXPECT_TRUE(recovered.state().skull != nullptr);
  }
  EXPECT_GE(killed_midway, runs - 2) << "the writer should be killed while writing";
}

}  // namespace
}  // namespace cranioplan
