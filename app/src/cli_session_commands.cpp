#include "cli_session_commands.h"

#include <memory>
#include <optional>

#include "cli_output.h"
#include "cli_planning.h"
#include "cranioplan/algorithms/io/file_io.h"
#include "cranioplan/algorithms/io/write_mesh.h"
#include "cranioplan/sessions/audit.h"
#include "cranioplan/sessions/marker_files.h"
#include "cranioplan/sessions/session.h"

namespace cranioplan::cli {

Json plan_state_json(const PlanState& s) {
  Json j;
  Json steps = Json::array();
  for (const auto& step : wizard_steps()) {
    std::string missing;
    const bool done = step_complete(s, step.number, &missing);
    Json row{{"step", step.number}, {"title", step.title}, {"done", done}};
    if (!done) row["missing"] = missing;
    if (s.stale.count(step.number)) row["stale"] = s.stale.at(step.number);
    steps.push_back(row);
  }
  j["steps"] = steps;
  if (s.skull) j["skull"] = Json{{"path", s.skull->path}, {"sha256", s.skull->sha256}};
  if (s.plane) j["plane"] = to_json(*s.plane);
  if (s.mirrored) j["mirror_transform"] = to_json(s.mirror_transform());
  j["markers"] = s.markers.size();
  if (s.implant) {
    const auto& r = s.implant->result();
    j["implant"] = Json{{"triangles", r.mesh.n_faces()},
                        {"watertight", r.watertight},
                        {"sha256_stl", s.implant->stl_sha256()}};
    j["quality"] = to_json(s.implant->quality());
  }
  Json exports = Json::array();
  for (const auto& e : s.exports)
    exports.push_back({{"path", e.path},
                       {"recorded_sha256", e.recorded_sha256},
                       {"replayed_sha256", e.replayed_sha256}});
  j["exports"] = exports;
  return j;
}

namespace {

Subcommand add_replay(CLI::App& app, const bool& json) {
  struct Opts {
    std::string session, output;
  };
  auto o = std::make_shared<Opts>();
  auto* cmd = app.add_subcommand("replay", "Rebuild a saved plan headlessly from its commands");
  cmd->add_option("SESSION", o->session, "session (.json)")->required();
  cmd->add_option("-o,--output", o->output, "write the plan's implant (.stl or .ply)");
  return {cmd, [o, &json] {
            const Session s = Session::open(o->session);
            Json j = plan_state_json(s.state());
            j["commands"] = s.effective_commands().size();
            if (!o->output.empty()) {
              if (!s.state().implant) {
                j["error"] = "the plan has no implant to write";
                print_result(j, json);
                return kUnusable;
              }
              const auto& skull = s.state().skull;
              write_mesh(s.state().implant->result().mesh, o->output,
                         skull ? skull->surface->loaded.file_space : MeshSpace::Undeclared);
              j["output"] = o->output;
            }
            print_result(j, json);
            return kOk;
          }};
}

Subcommand add_points(CLI::App& app, const bool& json) {
  struct Opts {
    std::string session, markers, landmarks;
  };
  auto o = std::make_shared<Opts>();
  auto* cmd = app.add_subcommand(
      "points", "Write a plan's markers and landmarks (.json, .csv or Slicer .mrk.json)");
  cmd->add_option("SESSION", o->session, "session (.json)")->required();
  cmd->add_option("--markers", o->markers, "markers to write (.json, .csv or .mrk.json)");
  cmd->add_option("--landmarks", o->landmarks, "landmarks to write (.json or .mrk.json)");
  return {cmd, [o, &json] {
            const Session s = Session::open(o->session);
            const PlanState& state = s.state();
            Json j{{"markers", state.markers.size()}};
            if (!o->markers.empty()) {
              write_markers_file(state.markers, o->markers);
              j["markers_file"] = o->markers;
            }
            if (!o->landmarks.empty()) {
              write_landmarks_file(state.landmarks, o->landmarks);
              j["landmarks_file"] = o->landmarks;
            }
            print_result(j, json);
            return kOk;
          }};
}

Subcommand add_export(CLI::App& app, const bool& json) {
  struct Opts {
    std::string session, output;
    bool mould = false;
    MouldParams mould_params;
  };
  auto o = std::make_shared<Opts>();
  auto* cmd = app.add_subcommand(
      "export", "Export a plan's implant as a recorded command (.stl, .ply or .3mf)");
  cmd->add_option("SESSION", o->session, "session (.json); saved with the export recorded")
      ->required();
  cmd->add_option("-o,--output", o->output, "the implant (.stl, .ply or .3mf)")->required();
  cmd->add_flag("--mould", o->mould,
                "a .3mf with the two halves of a casting mould beside the implant");
  add_declared_options(cmd, o->mould_params, "mould-");
  return {
      cmd, [o, &json] {
        Session s = Session::open(o->session);
        const PushResult r = s.push(commands::export_implant(
            o->output, "", o->mould ? std::optional<MouldParams>(o->mould_params) : std::nullopt));
        Json j{{"exported", r.accepted}, {"message", r.message}};
        if (!r.accepted) {
          print_result(j, json);
          return kUnusable;
        }
        s.save(o->session);
        j["output"] = o->output;
        j["sha256"] = s.effective_commands().back().params["sha256"];
        print_result(j, json);
        return kOk;
      }};
}

Subcommand add_approve(CLI::App& app, const bool& json) {
  struct Opts {
    std::string session, by, role = "neurosurgeon";
  };
  auto o = std::make_shared<Opts>();
  auto* cmd = app.add_subcommand(
      "approve", "Sign off a plan's implant as it stands (any later change withdraws it)");
  cmd->add_option("SESSION", o->session, "session (.json); saved with the approval recorded")
      ->required();
  cmd->add_option("--by", o->by, "who approves (name)")->required();
  cmd->add_option("--role", o->role, "in what role")->capture_default_str();
  return {cmd, [o, &json] {
            Session s = Session::open(o->session);
            const PushResult r = s.push(commands::approve(o->by, o->role));
            Json j{{"approved", r.accepted}, {"message", r.message}};
            if (!r.accepted) {
              print_result(j, json);
              return kUnusable;
            }
            s.save(o->session);
            j["implant_sha256"] = s.state().approval->implant_sha256;
            j["time"] = s.journal().back().time;
            print_result(j, json);
            return kOk;
          }};
}

Subcommand add_verify(CLI::App& app, const bool& json) {
  auto session = std::make_shared<std::string>();
  auto* cmd = app.add_subcommand(
      "verify", "Check a plan: inputs' hashes, hash chain, replay of every export (exit 4 if not)");
  cmd->add_option("SESSION", *session, "session (.json)")->required();
  return {cmd, [session, &json] {
            const VerifyReport r = verify_session(*session);
            Json j;
            j["ok"] = r.ok();
            for (const auto& c : r.checks) j[c.name] = (c.ok ? "holds: " : "FAILS: ") + c.detail;
            print_result(j, json);
            return r.ok() ? kOk : kVerifyFailed;
          }};
}

Subcommand add_audit(CLI::App& app, const bool& json) {
  struct Opts {
    std::string session, html;
  };
  auto o = std::make_shared<Opts>();
  auto* cmd = app.add_subcommand("audit", "A plan's timeline: who, when, step, what, how long");
  cmd->add_option("SESSION", o->session, "session (.json)")->required();
  cmd->add_option("--html", o->html, "also write the timeline as HTML");
  return {cmd, [o, &json] {
            const SessionDocument doc = read_session_document(o->session);
            if (!o->html.empty()) {
              const VerifyReport v = verify_session(o->session);
              write_file_atomically(o->html, audit_html(doc, &v));
            }
            if (json) {
              Json rows = Json::array();
              for (const auto& r : audit_rows(doc))
                rows.push_back({{"seq", r.seq},
                                {"time", r.time},
                                {"user", r.user},
                                {"event", r.event},
                                {"step", r.step},
                                {"what", r.what},
                                {"duration_ms", r.duration_ms},
                                {"undone", r.undone}});
              const StepDurations d = step_durations(doc.header, doc.journal);
              Json steps = Json::object();
              for (const auto& s : wizard_steps())
                steps[std::to_string(s.number)] = d.seconds[s.number];
              print_result(
                  Json{{"timeline", rows}, {"step_seconds", steps}, {"total_seconds", d.total}},
                  true);
            } else {
              std::fputs(audit_text(doc).c_str(), stdout);
            }
            return kOk;
          }};
}

Subcommand add_training_report(CLI::App& app, const bool& json) {
  struct Opts {
    std::string session, reference, html;
  };
  auto o = std::make_shared<Opts>();
  auto* cmd = app.add_subcommand(
      "training-report", "A trainee's plan against an expert's: time per step, implant agreement");
  cmd->add_option("SESSION", o->session, "the trainee's session")->required();
  cmd->add_option("--reference", o->reference, "the expert's session")->required();
  cmd->add_option("--html", o->html, "also write the report as HTML");
  return {cmd, [o, &json] {
            const Session trainee = Session::open(o->session);
            const Session reference = Session::open(o->reference);
            const TrainingReport r = training_report(trainee, reference);
            if (!o->html.empty()) write_file_atomically(o->html, training_report_html(r));
            if (json) {
              Json steps = Json::array();
              for (const auto& s : wizard_steps())
                steps.push_back({{"step", s.number},
                                 {"trainee_s", r.trainee.seconds[s.number]},
                                 {"reference_s", r.reference.seconds[s.number]}});
              Json j{{"steps", steps},
                     {"trainee_total_s", r.trainee.total},
                     {"reference_total_s", r.reference.total}};
              if (r.agreement)
                j["agreement"] = to_json(*r.agreement);
              else
                j["note"] = r.note;
              print_result(j, true);
            } else {
              std::fputs(training_report_text(r).c_str(), stdout);
            }
            return kOk;
          }};
}

}  // namespace

std::vector<Subcommand> add_session_commands(CLI::App& app, const bool& json) {
  // In the order `--help` lists them.
  std::vector<Subcommand> out;
  out.push_back(add_replay(app, json));
  out.push_back(add_points(app, json));
  out.push_back(add_export(app, json));
  out.push_back(add_approve(app, json));
  out.push_back(add_verify(app, json));
  out.push_back(add_audit(app, json));
  out.push_back(add_training_report(app, json));
  return out;
}

}  // namespace cranioplan::cli
