#include "cranioplan/sessions/audit.h"

#include <Eigen/Eigenvalues>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <functional>
#include <limits>
#include <sstream>

#include "cranioplan/sessions/session_error.h"
#include "cranioplan/sessions/sha256.h"

namespace cranioplan {

namespace fs = std::filesystem;

bool VerifyReport::ok() const {
  for (const auto& c : checks)
    if (!c.ok) return false;
  return !checks.empty();
}

namespace {

std::string resolve(const std::string& recorded, const std::string& session_dir) {
  std::error_code ec;
  if (fs::exists(recorded, ec)) return recorded;
  for (const fs::path& candidate :
       {fs::path(session_dir) / recorded, fs::path(session_dir) / fs::path(recorded).filename()})
    if (fs::exists(candidate, ec)) return candidate.string();
  return {};
}

std::string fmt(const char* format, double value) {
  char buf[64];
  std::snprintf(buf, sizeof(buf), format, value);
  return buf;
}

std::string html_escape(const std::string& s) {
  std::string out;
  for (char c : s) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

const char* kHtmlHead =
    "<!DOCTYPE html><html><head><meta charset=\"utf-8\"><title>%s</title><style>"
    "body{font-family:sans-serif;margin:2em;color:#222}table{border-collapse:collapse}"
    "td,th{border:1px solid #bbb;padding:3px 8px;text-align:left;vertical-align:top}"
    "th{background:#eee}.undone{color:#999;text-decoration:line-through}.ok{color:#070}"
    ".bad{color:#b00;font-weight:bold}code{font-size:85%%}</style></head><body>";

std::string html_head(const std::string& title) {
  char buf[1024];
  std::snprintf(buf, sizeof(buf), kHtmlHead, html_escape(title).c_str());
  return buf;
}

std::string duration_text(double seconds) {
  const int s = static_cast<int>(std::lround(seconds));
  char buf[32];
  std::snprintf(buf, sizeof(buf), "%d:%02d", s / 60, s % 60);
  return buf;
}

}  // namespace

namespace {

// The sign-off, for a plan that has one or had one: who approved and when (the journal's time
// of the approval), and which exported files on disk are the approved implant. Not approved (or
// withdrawn by a later change), or an approved export changed on disk: not ok.
std::optional<VerifyCheck> approval_check(const Session& session, const SessionDocument& doc,
                                          const std::string& dir) {
  const PlanState& s = session.state();
  if (!s.approval && s.approval_withdrawn.empty()) return std::nullopt;
  VerifyCheck check{"approval", false, ""};
  if (!s.approval) {
    check.detail = s.approval_withdrawn + ": not approved";
    return check;
  }
  std::string when;
  for (const JournalEntry& e : doc.journal)
    if (e.event == "do" && e.command && e.command->type == CommandType::Approve &&
        e.command->params.value("implant_sha256", std::string()) == s.approval->implant_sha256)
      when = e.time;
  check.ok = true;
  check.detail = "approved by " + s.approval->by + " (" + s.approval->role + ")" +
                 (when.empty() ? "" : " at " + when) + ", implant SHA-256 " +
                 s.approval->implant_sha256.substr(0, 12) + "…";
  std::string approved, other;
  for (const ExportRecord& e : s.exports) {
    if (e.implant_sha256 != s.approval->implant_sha256) {
      other += (other.empty() ? "" : ", ") + e.path;
      continue;
    }
    const std::string found = resolve(e.path, dir);
    std::string state = "unchanged";
    if (found.empty()) {
      state = "not found";
    } else if (sha256_file(found) != e.recorded_sha256) {
      state = "CHANGED on disk";
      check.ok = false;
    }
    approved += (approved.empty() ? "" : ", ") + e.path + " (" + state + ")";
  }
  check.detail += approved.empty() ? "; no export of the approved implant"
                                   : "; the approved implant in " + approved;
  if (!other.empty()) check.detail += "; exports of another implant, not approved: " + other;
  return check;
}

}  // namespace

VerifyReport verify_session(const std::string& path) {
  VerifyReport report;
  const SessionDocument doc = read_session_document(path);
  const std::string dir = fs::path(path).parent_path().string();

  VerifyCheck inputs{"inputs", true, ""};
  int n_inputs = 0;
  for (const auto& c : doc.commands) {
    // The skull, an attached CT, and a shape model a proposal was guided by.
    const bool model = c.type == CommandType::ProposeMarkers && c.params.contains("shape_model") &&
                       c.params["shape_model"].is_object();
    if (c.type != CommandType::LoadSkull && c.type != CommandType::AttachCt && !model) continue;
    const Json& input = model ? c.params["shape_model"] : c.params;
    ++n_inputs;
    const std::string recorded = input.value("path", std::string());
    const std::string found = resolve(recorded, dir);
    if (found.empty()) {
      inputs.ok = false;
      inputs.detail += recorded + ": missing. ";
    } else if (sha256_file(found) != input.value("sha256", std::string())) {
      inputs.ok = false;
      inputs.detail += found + (model ? ": the shape model" : ": the skull file") +
                       " changed since this plan was made. ";
    }
  }
  if (inputs.ok) inputs.detail = std::to_string(n_inputs) + " input file(s) unchanged (SHA-256)";
  report.checks.push_back(inputs);

  VerifyCheck chain{"hash chain", true, ""};
  if (auto bad = first_broken_link(doc.header, doc.journal)) {
    chain.ok = false;
    chain.detail = "broken at journal entry " + std::to_string(*bad + 1) + " of " +
                   std::to_string(doc.journal.size()) +
                   ": the session was changed after it was written";
  } else {
    chain.detail = std::to_string(doc.journal.size()) + " journal entries, every link holds";
  }
  report.checks.push_back(chain);

  VerifyCheck replay{"replay", false, ""};
  if (!inputs.ok || !chain.ok) {
    replay.detail = "not run: the inputs or the journal do not hold";
    report.checks.push_back(replay);
    return report;
  }
  try {
    const Session session = Session::open(path);
    const auto& exports = session.state().exports;
    int matching = 0;
    replay.ok = true;
    for (const auto& e : exports) {
      if (e.recorded_sha256 == e.replayed_sha256) {
        ++matching;
      } else {
        replay.ok = false;
        replay.detail += e.path + ": the replayed implant differs from the one exported. ";
      }
    }
    if (replay.ok)
      replay.detail = std::to_string(session.effective_commands().size()) + " commands replayed; " +
                      std::to_string(matching) + " of " + std::to_string(exports.size()) +
                      " export(s) reproduced byte for byte";
    report.checks.push_back(replay);
    if (const auto approval = approval_check(session, doc, dir)) report.checks.push_back(*approval);
    return report;
  } catch (const Error& e) {
    replay.detail = e.what();
  }
  report.checks.push_back(replay);
  return report;
}

StepDurations step_durations(const SessionHeader& header, const std::vector<JournalEntry>& journal,
                             double idle_cap_s) {
  StepDurations d;
  double previous = parse_iso8601(header.info.created);
  int last_step = 1;
  std::vector<Command> stack;
  size_t index = 0;
  for (const auto& e : journal) {
    int step = last_step;
    if (e.event == "do" || e.event == "merge") {
      if (e.command->meta.step >= kLoadStep) step = e.command->meta.step;
      if (e.event == "do") {
        stack.resize(index);
        stack.push_back(*e.command);
        ++index;
      } else if (index > 0) {
        stack[index - 1] = *e.command;
      }
    } else if (e.event == "undo" && index > 0) {
      step = std::max(1, stack[index - 1].meta.step);
      --index;
    } else if (e.event == "redo" && index < stack.size()) {
      step = std::max(1, stack[index].meta.step);
      ++index;
    }
    const double t = parse_iso8601(e.time);
    if (std::isfinite(t) && std::isfinite(previous)) {
      const double gap = std::clamp(t - previous, 0.0, idle_cap_s);
      d.seconds[step] += gap;
      d.total += gap;
    }
    if (std::isfinite(t)) previous = t;
    last_step = step;
  }
  return d;
}

std::vector<AuditRow> audit_rows(const SessionDocument& doc) {
  std::vector<AuditRow> rows;
  std::vector<Command> stack;
  std::vector<size_t> stack_rows;  // the row that did each stack entry
  size_t index = 0;
  for (const auto& e : doc.journal) {
    AuditRow row;
    row.seq = e.seq;
    row.time = e.time;
    row.user = e.user;
    row.event = e.event;
    if (e.command) {
      row.step = e.command->meta.step;
      row.what = describe(*e.command);
      row.params = e.command->params.dump();
      row.duration_ms = e.command->meta.duration_ms;
    }
    if (e.event == "do") {
      stack.resize(index);
      stack_rows.resize(index);
      stack.push_back(*e.command);
      stack_rows.push_back(rows.size());
      ++index;
    } else if (e.event == "merge" && index > 0) {
      stack[index - 1] = *e.command;
    } else if (e.event == "undo" && index > 0) {
      --index;
      row.step = stack[index].meta.step;
      row.what = describe(stack[index]);
    } else if (e.event == "redo" && index < stack.size()) {
      row.step = stack[index].meta.step;
      row.what = describe(stack[index]);
      ++index;
    }
    rows.push_back(row);
  }
  // A do whose command is not among the effective ones was undone (or dropped by a later push).
  std::vector<bool> effective(rows.size(), false);
  for (size_t i = 0; i < index; ++i) effective[stack_rows[i]] = true;
  for (size_t i = 0; i < rows.size(); ++i)
    if (rows[i].event == "do") rows[i].undone = !effective[i];
  return rows;
}

std::string audit_text(const SessionDocument& doc) {
  std::ostringstream out;
  out << "Plan " << doc.header.info.case_id << " by " << doc.header.info.user << ", created "
      << doc.header.info.created << " (Cranioplan " << doc.header.app_version << ")\n";
  out << doc.commands.size() << " commands in the plan, " << doc.journal.size()
      << " journal events\n\n";
  for (const auto& r : audit_rows(doc)) {
    char buf[200];
    std::snprintf(buf, sizeof(buf), "%4d  %s  %-10s step %d  %-6s ", r.seq, r.time.c_str(),
                  r.user.c_str(), r.step, r.event.c_str());
    out << buf << r.what;
    if (r.event == "do" || r.event == "merge") out << "  (" << fmt("%.0f ms", r.duration_ms) << ")";
    if (r.undone) out << "  [undone]";
    if (!r.params.empty() && r.params != "{}") out << "\n        " << r.params.substr(0, 300);
    out << "\n";
  }
  const StepDurations d = step_durations(doc.header, doc.journal);
  out << "\nTime per step (m:ss)\n";
  for (const auto& s : wizard_steps())
    out << "  " << s.number << " " << s.title << ": " << duration_text(d.seconds[s.number]) << "\n";
  out << "  total: " << duration_text(d.total) << "\n";
  return out.str();
}

std::string audit_html(const SessionDocument& doc, const VerifyReport* verify) {
  std::ostringstream out;
  out << html_head("Cranioplan audit: " + doc.header.info.case_id);
  out << "<h1>Plan " << html_escape(doc.header.info.case_id) << "</h1><p>By "
      << html_escape(doc.header.info.user) << ", created " << html_escape(doc.header.info.created)
      << ", Cranioplan " << html_escape(doc.header.app_version) << ". " << doc.commands.size()
      << " commands in the plan, " << doc.journal.size() << " journal events.</p>";
  if (verify) {
    out << "<h2>Verification</h2><ul>";
    for (const auto& c : verify->checks)
      out << "<li class=\"" << (c.ok ? "ok" : "bad") << "\">" << html_escape(c.name) << ": "
          << (c.ok ? "holds" : "FAILS") << " — " << html_escape(c.detail) << "</li>";
    out << "</ul>";
  }
  out << "<h2>Timeline</h2><table><tr><th>#</th><th>time (UTC)</th><th>user</th><th>step</th>"
         "<th>event</th><th>what</th><th>parameters</th><th>ms</th></tr>";
  for (const auto& r : audit_rows(doc)) {
    out << "<tr" << (r.undone ? " class=\"undone\"" : "") << "><td>" << r.seq << "</td><td>"
        << html_escape(r.time) << "</td><td>" << html_escape(r.user) << "</td><td>" << r.step
        << "</td><td>" << r.event << "</td><td>" << html_escape(r.what) << "</td><td><code>"
        << html_escape(r.params.substr(0, 400)) << "</code></td><td>"
        << (r.event == "do" || r.event == "merge" ? fmt("%.0f", r.duration_ms) : std::string())
        << "</td></tr>";
  }
  out << "</table>";
  const StepDurations d = step_durations(doc.header, doc.journal);
  out << "<h2>Time per step</h2><table><tr><th>step</th><th>m:ss</th></tr>";
  for (const auto& s : wizard_steps())
    out << "<tr><td>" << s.number << " " << html_escape(s.title) << "</td><td>"
        << duration_text(d.seconds[s.number]) << "</td></tr>";
  out << "<tr><th>total</th><th>" << duration_text(d.total) << "</th></tr></table></body></html>";
  return out.str();
}

TrainingReport training_report(const Session& trainee, const Session& reference,
                               const CompareParams& params) {
  TrainingReport r;
  r.trainee_user = trainee.header().info.user;
  r.reference_user = reference.header().info.user;
  r.trainee = step_durations(trainee.header(), trainee.journal());
  r.reference = step_durations(reference.header(), reference.journal());
  const auto& a = trainee.state().implant;
  const auto& b = reference.state().implant;
  if (!a || !b) {
    r.note = !a ? "the trainee's plan has no implant" : "the reference plan has no implant";
    return r;
  }
  r.trainee_volume_mm3 = std::abs(signed_volume(a->result().mesh));
  r.reference_volume_mm3 = std::abs(signed_volume(b->result().mesh));
  r.agreement = compare_implants(
      a->result().mesh, b->result().mesh,
      trainee.state().skull ? &trainee.state().skull->surface->mesh : nullptr, params);
  return r;
}

std::string training_report_text(const TrainingReport& r) {
  std::ostringstream out;
  out << "Training report: " << r.trainee_user << " against " << r.reference_user << "\n\n";
  char buf[200];
  std::snprintf(buf, sizeof(buf), "  %-34s %9s %9s %7s\n", "step", "trainee", "reference", "ratio");
  out << buf;
  for (const auto& s : wizard_steps()) {
    const double t = r.trainee.seconds[s.number], ref = r.reference.seconds[s.number];
    std::snprintf(buf, sizeof(buf), "  %d %-32s %9s %9s %7s\n", s.number, s.title,
                  duration_text(t).c_str(), duration_text(ref).c_str(),
                  ref > 0 ? fmt("%.2f", t / ref).c_str() : "-");
    out << buf;
  }
  std::snprintf(
      buf, sizeof(buf), "  %-34s %9s %9s %7s\n", "total", duration_text(r.trainee.total).c_str(),
      duration_text(r.reference.total).c_str(),
      r.reference.total > 0 ? fmt("%.2f", r.trainee.total / r.reference.total).c_str() : "-");
  out << buf << "\n";
  if (r.agreement) {
    const CompareResult& c = *r.agreement;
    std::snprintf(buf, sizeof(buf),
                  "Implant agreement: DSC %.3f, boundary DSC %.3f, HD95 %.2f mm, HD %.2f mm\n"
                  "Volumes: trainee %.0f mm³, reference %.0f mm³\n",
                  c.dice, c.boundary_dice, c.hd95_mm, c.hausdorff_mm, r.trainee_volume_mm3,
                  r.reference_volume_mm3);
    out << buf;
  } else {
    out << "Implant agreement: not measured — " << r.note << "\n";
  }
  return out.str();
}

std::string training_report_html(const TrainingReport& r) {
  std::ostringstream out;
  out << html_head("Cranioplan training report");
  out << "<h1>Training report</h1><p>Trainee " << html_escape(r.trainee_user)
      << " against reference " << html_escape(r.reference_user) << ".</p>";
  out << "<h2>Time per step (m:ss)</h2><table><tr><th>step</th><th>trainee</th>"
         "<th>reference</th><th>ratio</th></tr>";
  for (const auto& s : wizard_steps()) {
    const double t = r.trainee.seconds[s.number], ref = r.reference.seconds[s.number];
    out << "<tr><td>" << s.number << " " << html_escape(s.title) << "</td><td>" << duration_text(t)
        << "</td><td>" << duration_text(ref) << "</td><td>"
        << (ref > 0 ? fmt("%.2f", t / ref) : std::string("-")) << "</td></tr>";
  }
  out << "<tr><th>total</th><th>" << duration_text(r.trainee.total) << "</th><th>"
      << duration_text(r.reference.total) << "</th><th>"
      << (r.reference.total > 0 ? fmt("%.2f", r.trainee.total / r.reference.total)
                                : std::string("-"))
      << "</th></tr></table><h2>Implant agreement</h2>";
  if (r.agreement) {
    const CompareResult& c = *r.agreement;
    out << "<table><tr><th>DSC</th><td>" << fmt("%.3f", c.dice) << "</td></tr><tr><th>boundary "
        << "DSC</th><td>" << fmt("%.3f", c.boundary_dice) << "</td></tr><tr><th>HD95</th><td>"
        << fmt("%.2f mm", c.hd95_mm) << "</td></tr><tr><th>HD</th><td>"
        << fmt("%.2f mm", c.hausdorff_mm) << "</td></tr><tr><th>volume trainee</th><td>"
        << fmt("%.0f mm³", r.trainee_volume_mm3) << "</td></tr><tr><th>volume reference</th><td>"
        << fmt("%.0f mm³", r.reference_volume_mm3) << "</td></tr></table>";
  } else {
    out << "<p>Not measured: " << html_escape(r.note) << "</p>";
  }
  out << "</body></html>";
  return out.str();
}

std::vector<std::string> quality_advice(const QualityReport& r, const ImplantParams& params) {
  std::vector<std::string> out;
  if (r.printable) return out;
  const QualityParams limits;
  const bool fitted = params.fit_to_bone_mm > 0;
  const bool gap = r.rim_gap_mm > limits.max_rim_gap_mm ||
                   (r.clearance_asked && r.clearance_high_mm > limits.max_rim_gap_mm);
  const bool overlap = r.penetration_mm3 > limits.max_penetration_mm3;
  const bool crossing = r.self_intersections > 0 || !r.watertight || !r.manifold || !r.outward;
  if (!fitted && (gap || overlap || crossing)) {
    out.push_back(
        "Set \"Fit to the bone\" to 4 mm (step 7) and build again: the implant is then made to "
        "meet the cut face all around, without entering the bone or folding over itself.");
  } else {
    if (gap)
      out.push_back(
          "The edge stands off the bone where the red ball shows: move the edge markers there "
          "onto the bone's edge (step 5), or widen \"Fit to the bone\", and build again.");
    if (overlap)
      out.push_back(
          "The implant enters the bone: check the outer surface markers near the rim (step 6), "
          "or raise the material's edge clearance.");
    if (crossing)
      out.push_back(
          "The surfaces fold over themselves: smooth the markers (step 8) or delete markers "
          "that lie out of line, and build again.");
  }
  if (r.taper_reach_mm < 0 || r.corner_reach_mm > limits.max_corner_mm ||
      r.taper_reach_mm > limits.max_taper_mm)
    out.push_back(
        "Parts are thinner than the minimum: set a thickness (\"Thickness without inner "
        "markers\" or the material's plate thickness), or check the inner surface markers.");
  if (r.holes_blocked > 0)
    out.push_back("Move or remove the holes that do not go through (step 7, Remove a hole).");
  if (r.screws_blocked > 0 || r.tab_gap_mm > limits.max_tab_gap_mm ||
      r.tab_gap_mm < -limits.max_tab_gap_mm ||
      (r.tab_bone_mm >= 0 && r.tab_bone_mm < limits.tab_min_bone_mm) ||
      (r.tab_midline_mm >= 0 && r.tab_midline_mm < limits.tab_midline_mm))
    out.push_back(
        "Drag the tabs named above along the rim to thicker bone, away from the midline.");
  if (r.clearance_asked && -r.clearance_low_mm > limits.clearance_tolerance_mm)
    out.push_back("Lower the clearance asked, or widen \"Fit to the bone\".");
  if (out.empty())
    out.push_back("Read the problems listed in the Quality panel (right) and build again.");
  return out;
}

namespace {
// "2026-12-07T06:09:07.055Z" as "2026-12-07 06:09 UTC"; "—" for none.
std::string readable_time(const std::string& iso) {
  if (iso.size() < 16 || iso[10] != 'T') return iso.empty() ? std::string("—") : iso;
  return iso.substr(0, 10) + " " + iso.substr(11, 5) + " UTC";
}
}  // namespace

namespace {
// The verdict itself: printable (with a finding to check, or not), or refused with what to try.
std::string verdict(const QualityReport& r, const ImplantParams& params,
                    const SoftTissueCheck* tissue, bool finding) {
  if (r.printable && finding)
    return "<p style='color:#8a5a00'><b>Printable, with a finding to check before approval:</b> "
           "brain or dura reaches " +
           fmt("%.1f", tissue->intrusion_reach_mm) +
           " mm above the implant's inner surface (red on the CT slices, seen in View → CT window "
           "→ Soft tissue; the Quality panel on the right has the figures).</p>";
  if (r.printable)
    return "<p style='color:#070'><b>Printable:</b> the quality check passes (the full report "
           "is in the Quality panel on the right).</p>";
  std::string h =
      "<p style='color:#a00'><b>Not printable: the quality check refuses this "
      "implant.</b></p><ul>";
  for (const std::string& reason : r.reasons) h += "<li>" + html_escape(reason) + "</li>";
  h += "</ul><p><b>What to try:</b></p><ul>";
  for (const std::string& a : quality_advice(r, params)) h += "<li>" + html_escape(a) + "</li>";
  return h + "</ul>";
}
}  // namespace

std::string quality_verdict_html(const QualityReport& r, const ImplantParams& params,
                                 const SoftTissueCheck* tissue) {
  const bool finding = tissue && tissue->checked && tissue->finding;
  // The defect ran into the scan's end: the implant ends there, and what lies beyond was not
  // scanned. Said with every verdict, printable or not.
  const std::string scan_end =
      !r.ends_at_scan_end
          ? std::string()
          : "<p style='color:#8a5a00'><b>The implant ends where the scan ended:</b> the defect "
            "runs into the border of the scan, and the bone beyond it is unknown. Check on the "
            "patient or a wider scan that the opening ends there.</p>";
  return scan_end + verdict(r, params, tissue, finding);
}

std::string quality_report_html(const QualityReport& r, const SoftTissueCheck* tissue) {
  auto fixed = [](double v, int decimals) {
    char buf[64];
    std::snprintf(buf, sizeof(buf), "%.*f", decimals, v);
    return std::string(buf);
  };
  auto yes = [](bool b) { return std::string(b ? "yes" : "<b>no</b>"); };
  std::string h = "<table cellspacing=2>";
  auto row = [&](const std::string& k, const std::string& v) {
    h += "<tr><td>" + k + "</td><td><b>" + v + "</b></td></tr>";
  };
  row("Printable", r.printable ? "yes" : "NO");
  if (!r.material_name.empty()) row("Material", html_escape(r.material_name));
  row("Watertight", yes(r.watertight));
  row("Manifold", yes(r.manifold));
  row("Outward normals", yes(r.outward));
  row("Self-intersections", std::to_string(r.self_intersections));
  row("Pieces", std::to_string(r.pieces));
  row("Volume", fixed(r.volume_mm3, 0) + " mm³");
  row("Area", fixed(r.area_mm2, 0) + " mm²");
  if (r.mass_g > 0) row("Mass", fixed(r.mass_g, 1) + " g");
  // The least thickness along the faces' normals is that of the tapered edge (0 where it
  // meets the bone): shown as such, not as a verdict.
  row("Thickness median / max", fixed(r.thickness_median_mm, 1) + " / " +
                                    fixed(r.thickness_max_mm, 1) + " mm (" +
                                    fixed(r.thickness_min_mm, 1) + " at the tapered edge)");
  row("Thinner than the minimum", r.taper_reach_mm < 0
                                      ? std::string("everywhere")
                                      : fixed(r.thin_volume_mm3, 1) + " mm³: edge on the bone " +
                                            fixed(r.taper_reach_mm, 1) + " mm wide, elsewhere " +
                                            fixed(r.corner_reach_mm, 1) + " mm");
  // Where the edge stands off the bone more than automatic plans aim for, on the row that
  // judges it.
  const std::optional<Eigen::Vector3d> mark = rim_gap_to_mark(r);
  const std::string where = mark ? at_point_text(*mark) : std::string();
  if (r.rim_gap_mm >= 0)
    row("Gap to bone (rim)",
        fixed(r.rim_gap_mm, 2) + " mm" + (r.clearance_asked ? std::string() : where));
  if (r.clearance_asked && r.rim_gap_mm >= 0) {
    auto signed_mm = [&](double v) { return (v >= 0 ? "+" : "−") + fixed(std::abs(v), 2); };
    row("Edge gap per 5° arc, less the clearance asked",
        signed_mm(r.clearance_low_mm) + " to " + signed_mm(r.clearance_high_mm) + " mm" + where);
  }
  if (r.penetration_mm3 >= 0) row("Overlap with skull", fixed(r.penetration_mm3, 1) + " mm³");
  if (r.ends_at_scan_end)
    row("Ends where the scan ended", "yes: the bone beyond is unknown (no gap counted there)");
  if (r.holes > 0)
    row("Perforations",
        std::to_string(r.holes) +
            (r.holes_blocked == 0 ? std::string(", all through")
                                  : ", " + std::to_string(r.holes_blocked) + " <b>blocked</b>"));
  if (r.tabs > 0) {
    row("Fixation tabs", std::to_string(r.tabs) + ", underside up to " + fixed(r.tab_gap_mm, 2) +
                             " mm off the bone" +
                             (r.screws_blocked == 0 ? std::string(", screw holes through")
                                                    : ", " + std::to_string(r.screws_blocked) +
                                                          " screw holes <b>blocked</b>"));
    row("Bone under the screws (thinnest)", fixed(r.tab_bone_mm, 1) + " mm");
    if (r.tab_midline_mm >= 0)
      row("Tabs from the midsagittal plane (nearest)", fixed(r.tab_midline_mm, 1) + " mm");
  }
  if (tissue && tissue->checked) {
    row("Brain or dura in the implant's place (CT)",
        fixed(tissue->intrusion_mm3, 0) + " mm³" +
            (tissue->intrusion_mm3 > 0
                 ? ", up to " + fixed(tissue->intrusion_reach_mm, 1) + " mm above its inner surface"
                 : std::string()));
    if (tissue->sunken_scalp_mm3 > 0)
      row("Sunken scalp in its place (lifted by it)", fixed(tissue->sunken_scalp_mm3, 0) + " mm³");
    row("Free space under the inner surface",
        tissue->intrusion_mm3 > 0           ? std::string("none (tissue reaches into it)")
        : std::isfinite(tissue->closest_mm) ? fixed(tissue->closest_mm, 1) + " mm to soft tissue"
                                            : std::string("no soft tissue near"));
  }
  h += "</table>";
  if (tissue && tissue->checked && tissue->finding)
    h += "<p style='color:#a00'><b>Check on the CT slices:</b> " + html_escape(tissue->message) +
         " (red on the slices).</p>";
  else if (tissue && tissue->checked && (tissue->intrusion_mm3 > 0 || tissue->sunken_scalp_mm3 > 0))
    h += "<p>" + html_escape(tissue->message) + ".</p>";
  if (!r.reasons.empty()) {
    h += "<p><b>Problems:</b></p><ul>";
    for (const auto& reason : r.reasons) h += "<li>" + html_escape(reason) + "</li>";
    h += "</ul>";
  }
  return h;
}

namespace {

// The design report's parts, each a piece of HTML.

std::string fixed_mm(double v, int decimals) {
  return fmt(("%." + std::to_string(decimals) + "f").c_str(), v);
}

std::string point_mm(const Eigen::Vector3d& x) {
  return fixed_mm(x.x(), 1) + ", " + fixed_mm(x.y(), 1) + ", " + fixed_mm(x.z(), 1);
}

std::string table_row(const std::string& k, const std::string& v) {
  return "<tr><th>" + k + "</th><td>" + v + "</td></tr>";
}

// "2026-12-07T06:09:07.055Z" as "2026-12-07 06:09 UTC".
std::string minutes_utc(const std::string& iso) {
  if (iso.size() < 16 || iso[10] != 'T') return iso.empty() ? std::string("—") : iso;
  return iso.substr(0, 10) + " " + iso.substr(11, 5) + " UTC";
}

// Identity: whose plan this is, who made it, when, with what.
std::string identity_html(const Session& session, const std::string& case_id,
                          const std::string& program_version) {
  const SessionHeader& header = session.header();
  std::string skull_file;
  for (const Command& cmd : session.effective_commands())
    if (cmd.type == CommandType::LoadSkull) skull_file = cmd.params.value("path", std::string());
  return "<table width=100%>" +
         table_row("Case (patient) ID", "<b>" + html_escape(case_id) + "</b>") +
         table_row("Planned by", html_escape(header.info.user.empty() ? "—" : header.info.user)) +
         table_row("Plan started", html_escape(minutes_utc(header.info.created))) +
         table_row("Last change", html_escape(minutes_utc(session.journal().empty()
                                                              ? std::string()
                                                              : session.journal().back().time))) +
         table_row("Skull from",
                   html_escape(std::filesystem::path(skull_file).filename().string())) +
         table_row("Program", "Cranioplan " + html_escape(program_version)) + "</table>";
}

// The verdict: printable or not, a finding to check, an implant cut at the scan's end.
std::string verdict_html(const QualityReport& q, const SoftTissueCheck* tissue) {
  std::string h;
  if (!q.printable)
    h += "<p class=bad>NOT printable: the quality check refuses this implant.</p>";
  else if (tissue && tissue->checked && tissue->finding)
    h += "<p style='color:#8a5a00'><b>Printable, with a finding to check before approval:</b> "
         "brain or dura reaches " +
         fixed_mm(tissue->intrusion_reach_mm, 1) +
         " mm above the implant's inner surface (Quality, and the CT slices on page 3).</p>";
  else
    h += "<p class=ok><b>Printable:</b> the quality check passes.</p>";
  if (q.ends_at_scan_end)
    h += "<p style='color:#8a5a00'><b>The implant ends where the scan ended:</b> the defect runs "
         "into the border of the scan, and the bone beyond it is unknown.</p>";
  return h;
}

// The views of the skull on one page, the CT slices and the thickness map on the next, two
// pictures to a row.
std::string pictures_html(const std::vector<ReportImage>& images) {
  std::string pictures;
  const std::pair<std::vector<ReportImage::Kind>, const char*> pages[] = {
      {{ReportImage::Kind::View}, "The implant on the skull"},
      {{ReportImage::Kind::Slice, ReportImage::Kind::Thickness},
       "CT slices through the implant (its outline orange), and its thickness"}};
  for (const auto& [kinds, title] : pages) {
    std::vector<const ReportImage*> of;
    for (ReportImage::Kind kind : kinds)
      for (const ReportImage& image : images)
        if (image.kind == kind) of.push_back(&image);
    if (of.empty()) continue;
    pictures += std::string("<h2 style=\"page-break-before: always\">") + title + "</h2><table>";
    for (size_t k = 0; k < of.size(); ++k) {
      if (k % 2 == 0) pictures += "<tr>";
      pictures += "<td><img src=\"" + html_escape(of[k]->file) + "\" width=300><br>" +
                  html_escape(of[k]->caption) + "</td>";
      if (k % 2 == 1 || k + 1 == of.size()) pictures += "</tr>";
    }
    pictures += "</table>";
  }
  return pictures;
}

// The implant: material, extent along its principal axes, area, volume, mass, fit to the bone.
std::string implant_html(const PlanState& st, const ImplantData& implant) {
  const QualityReport& q = implant.quality();
  const ImplantResult& built = implant.result();
  const SkullMesh& mesh = built.mesh;
  const Eigen::Vector3d c = vertex_centroid(mesh);
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  for (auto vh : mesh.vertices()) {
    const Eigen::Vector3d d = to_eigen(mesh.point(vh)) - c;
    cov += d * d.transpose();
  }
  const Eigen::Matrix3d axes = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(cov).eigenvectors();
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(1e300), hi = -lo;
  for (auto vh : mesh.vertices()) {
    const Eigen::Vector3d d = axes.transpose() * (to_eigen(mesh.point(vh)) - c);
    lo = lo.cwiseMin(d);
    hi = hi.cwiseMax(d);
  }
  const Eigen::Vector3d extent = hi - lo;
  const std::optional<Material>& material =
      st.implant_params ? st.implant_params->material : std::optional<Material>();
  std::string h = "<h2>Implant</h2><table width=100%>";
  h += table_row("Material", material
                                 ? html_escape(describe(*material))
                                 : std::string("none chosen (the plan's surfaces as they are)"));
  h += table_row("Extent (principal axes)", fixed_mm(extent.z(), 1) + " × " +
                                                fixed_mm(extent.y(), 1) + " × " +
                                                fixed_mm(extent.x(), 1) + " mm");
  h += table_row("Surface area", fixed_mm(q.area_mm2, 0) + " mm²");
  h += table_row("Volume", fixed_mm(q.volume_mm3, 0) + " mm³");
  if (material)
    h += table_row("Mass", fixed_mm(q.volume_mm3 * 1e-3 * material->density_g_cm3, 1) + " g");
  h += table_row("Triangles", std::to_string(mesh.n_faces()));
  if (built.fit_to_bone_used_mm > 0.0)
    h += table_row(
        "Fitted to the bone",
        fixed_mm(built.fit_to_bone_used_mm, 1) + " mm over it" +
            (built.fit_margin_note.empty() ? std::string()
                                           : " (" + html_escape(built.fit_margin_note) + ")"));
  return h + "</table>";
}

// The perforations and the fixation tabs, a table each (`heading` starts each).
std::string holes_and_tabs_html(const ImplantResult& built,
                                const std::function<std::string(const char*)>& heading) {
  std::string h;
  if (!built.holes.empty()) {
    h += heading("Perforations");
    h += "<table><tr><th>#</th><th>Centre (mm)</th><th>Axis</th>"
         "<th>Placed</th></tr>";
    for (size_t k = 0; k < built.holes.size(); ++k) {
      const Hole& hole = built.holes[k];
      h += "<tr><td>" + std::to_string(k + 1) + "</td><td>" + point_mm(hole.center) + "</td><td>" +
           fixed_mm(hole.axis.x(), 2) + ", " + fixed_mm(hole.axis.y(), 2) + ", " +
           fixed_mm(hole.axis.z(), 2) + "</td><td>" + (hole.added ? "by hand" : "pattern") +
           "</td></tr>";
    }
    h += "</table>";
  }
  if (!built.tabs.empty()) {
    h += heading("Fixation tabs");
    h += "<table><tr><th>#</th><th>At the rim (mm)</th><th>Length × "
         "width × thickness</th><th>Screws</th><th>Bone under the screws</th><th>From the "
         "midline</th></tr>";
    for (size_t k = 0; k < built.tabs.size(); ++k) {
      const Tab& t = built.tabs[k];
      h += "<tr><td>" + std::to_string(k + 1) + "</td><td>" + point_mm(t.rim) + "</td><td>" +
           fixed_mm(t.length_mm, 1) + " × " + fixed_mm(t.width_mm, 1) + " × " +
           fixed_mm(t.thickness_mm, 1) + " mm</td><td>" + std::to_string(t.screws.size()) +
           "</td><td>" + fixed_mm(t.bone_mm, 1) + " mm</td><td>" +
           (std::isnan(t.midline_mm) ? std::string("—") : fixed_mm(t.midline_mm, 1) + " mm") +
           "</td></tr>";
    }
    h += "</table>";
  }
  return h;
}

// What is approved, and by whom (each line on its own, nothing to wrap), and the lines to sign
// by hand on paper, whatever the plan records.
std::string approval_html(const Session& session, const ImplantData& implant,
                          const std::string& case_id) {
  const PlanState& st = session.state();
  std::string h =
      "<p>The approver confirms having "
      "checked the implant above — its "
      "shape on the skull, its fit to the bone on the CT slices, its thickness and every "
      "finding of the quality table — and approves it for manufacture";
  if (st.implant_params && st.implant_params->material)
    h += " in " + html_escape(st.implant_params->material->name);
  h += " as the binary STL with SHA-256 <code>" + implant.stl_sha256() + "</code>, for case " +
       html_escape(case_id) + ".</p>";
  if (st.approval) {
    // When: the approve command's time in the journal.
    std::string when;
    for (const Command& c : session.effective_commands())
      if (c.type == CommandType::Approve) when = c.meta.ended;
    h += "<p class=ok><b>Approved</b> by " + html_escape(st.approval->by) + " (" +
         html_escape(st.approval->role) + ")" +
         (when.empty() ? std::string() : " on " + html_escape(readable_time(when))) +
         " for the implant with STL SHA-256 <code>" + st.approval->implant_sha256 +
         "</code>, recorded in the plan.</p>";
  } else if (!st.approval_withdrawn.empty()) {
    h += "<p class=bad>Not approved: " + html_escape(st.approval_withdrawn) + ".</p>";
  } else {
    h += "<p><b>Not approved yet.</b></p>";
  }
  h += "<table width=100%>";
  for (const char* line : {"Name", "Role", "Date", "Signature"})
    h += std::string("<tr><th width=25%>") + line + "</th><td height=34>&nbsp;</td></tr>";
  return h + "</table>";
}

// The inputs' and the outputs' hashes.
std::string provenance_html(const Session& session, const ImplantData& implant,
                            const std::string& program_version) {
  std::string h = "<h2>Provenance</h2><table>";
  for (const Command& cmd : session.effective_commands())
    if (cmd.type == CommandType::LoadSkull || cmd.type == CommandType::AttachCt)
      h += table_row(cmd.type == CommandType::LoadSkull ? "Skull" : "CT",
                     html_escape(cmd.params.value("path", std::string())) + "<br><code>SHA-256 " +
                         cmd.params.value("sha256", std::string()) + "</code>");
  h += table_row(
      "Plan (journal's last hash)",
      "<code>" + (session.journal().empty() ? std::string("—") : session.journal().back().hash) +
          "</code>");
  h += table_row("Implant (binary STL SHA-256)", "<code>" + implant.stl_sha256() + "</code>");
  h += table_row("Program", "Cranioplan " + html_escape(program_version));
  return h + "</table>";
}

}  // namespace

std::string design_report_html(const Session& session, const std::vector<ReportImage>& images,
                               const std::string& program_version, const SoftTissueCheck* tissue) {
  const PlanState& st = session.state();
  const ImplantData& implant = *st.implant;
  const std::string& case_id_given = session.header().info.case_id;
  const std::string case_id = case_id_given.empty() ? "(no case ID)" : case_id_given;
  std::string h = html_head("Cranioplan design report — " + case_id) +
                  "<h1>Implant design report — " + html_escape(case_id) + "</h1>";
  // Page 1: identity, verdict, the implant and its quality; then the pictures; then, on a page
  // of their own, the perforations and tabs, the approval and the provenance.
  h += identity_html(session, case_id, program_version);
  h += verdict_html(implant.quality(), tissue);
  h += implant_html(st, implant);
  h += "<h2>Quality</h2>" + quality_report_html(implant.quality(), tissue);
  h += pictures_html(images);
  bool paged = false;
  const auto heading = [&paged](const char* title) {
    const std::string tag = paged ? "<h2>" : "<h2 style=\"page-break-before: always\">";
    paged = true;
    return tag + title + "</h2>";
  };
  h += holes_and_tabs_html(implant.result(), heading);
  h += heading("Approval");
  h += approval_html(session, implant, case_id);
  h += provenance_html(session, implant, program_version);
  return h + "</body></html>";
}

}  // namespace cranioplan
