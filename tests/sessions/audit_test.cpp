#include "cranioplan/sessions/audit.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>

#include "cranioplan/algorithms/io/file_io.h"
#include "cranioplan/algorithms/planning/autoplan.h"
#include "cranioplan/model/error.h"
#include "cranioplan/sessions/autoplan_session.h"
#include "cranioplan/sessions/sha256.h"
#include "support/session_cases.h"
#include "support/test_files.h"

namespace cranioplan {
namespace {

namespace fs = std::filesystem;

using test::PlannedCase;
using test::push_ok;

const PlannedCase& planned() { return test::planned_defect_case(); }

// Tampering with any recorded parameter, in the command list or in the journal, is caught.
TEST(Verify, DetectsTamperingWithAnyRecordedParameter) {
  const PlannedCase& c = planned();
  const Json doc = read_json_file(c.session_path);
  std::vector<std::pair<std::string, Json::json_pointer>> leaves;
  std::function<void(const Json&, const Json::json_pointer&)> walk =
      [&](const Json& j, const Json::json_pointer& at) {
        if (j.is_object()) {
          for (auto it = j.begin(); it != j.end(); ++it) walk(it.value(), at / it.key());
        } else if (j.is_array()) {
          for (size_t i = 0; i < j.size(); ++i) walk(j[i], at / i);
        } else if (j.is_number() || j.is_boolean() ||
                   (j.is_string() && !j.get<std::string>().empty())) {
          leaves.emplace_back(at.to_string(), at);
        }
      };
  for (const char* list : {"commands", "journal"}) {
    const Json& l = doc[list];
    for (size_t i = 0; i < l.size(); ++i) {
      const Json::json_pointer base = Json::json_pointer("/" + std::string(list)) / i;
      const Json::json_pointer params =
          std::string(list) == "journal" ? base / "command" / "params" : base / "params";
      if (doc.contains(params)) walk(doc[params], params);
    }
  }
  ASSERT_GT(leaves.size(), 100u);
  int checked = 0;
  for (size_t k = 0; k < leaves.size(); k += std::max<size_t>(1, leaves.size() / 60)) {
    Json bad = doc;
    Json& v = bad[leaves[k].second];
    if (v.is_boolean())
      v = !v.get<bool>();
    else if (v.is_number_integer())
      v = v.get<long long>() + 1;
    else if (v.is_number())
      v = v.get<double>() + 1e-3;
    else
      v = v.get<std::string>() + "x";
    const std::string p = test::scratch_path("tampered.json");
    write_json_file(bad, p);
    bool detected = false;
    try {
      detected = !verify_session(p).ok();
    } catch (const Error&) {
      detected = true;  // unreadable as a session is also a failed verification
    }
    EXPECT_TRUE(detected) << "undetected change at " << leaves[k].first;
    ++checked;
  }
  EXPECT_GE(checked, 50);
}

TEST(Verify, CliExitsFourWhenAnyCheckFails) {
  const PlannedCase& c = planned();
  std::string out;
  EXPECT_EQ(test::run_command(std::string(CRANIOPLAN_CLI) + " verify " + c.session_path, &out), 0)
      << out;
  Json bad = read_json_file(c.session_path);
  bad["journal"][3]["time"] = "2001-01-01T00:00:00.000Z";
  const std::string p = test::scratch_path("bad_chain.json");
  write_json_file(bad, p);
  EXPECT_EQ(test::run_command(std::string(CRANIOPLAN_CLI) + " verify " + p, &out), 4);
  EXPECT_NE(out.find("journal entry 4"), std::string::npos) << out;
  const std::string replayed = test::scratch_path("replayed.stl");
  EXPECT_EQ(test::run_command(std::string(CRANIOPLAN_CLI) + " replay " + c.session_path + " -o " +
                              replayed),
            0);
  EXPECT_EQ(sha256_file(replayed), c.implant_sha);
}

// Sign-off from the command line: approve records who, in what role and the implant's hash
// (the journal gives when); verify names the approved exports and finds one changed on disk;
// a later change of the implant withdraws the approval visibly, and verify then fails.
TEST(Verify, ApprovalNamesTheApprovedExportsAndIsWithdrawnByAChange) {
  test::TempDir dir;
  const std::string plan = dir.path("plan.json");
  fs::copy_file(planned().session_path, plan);
  const std::string cli = std::string(CRANIOPLAN_CLI);
  std::string out;
  ASSERT_EQ(test::run_command(cli + " approve --json " + plan + " --by \"Dr Ada Lovelace\"", &out),
            0)
      << out;
  EXPECT_EQ(Json::parse(out)["implant_sha256"], planned().implant_sha);
  ASSERT_EQ(
      test::run_command(cli + " export --json " + plan + " -o " + dir.path("signed.stl"), &out), 0)
      << out;
  ASSERT_EQ(test::run_command(cli + " verify --json " + plan, &out), 0) << out;
  const std::string approval = Json::parse(out)["approval"];
  EXPECT_NE(approval.find("holds: approved by Dr Ada Lovelace (neurosurgeon) at 20"),
            std::string::npos)
      << approval;
  EXPECT_NE(approval.find("signed.stl (unchanged)"), std::string::npos) << approval;
  const Session approved = Session::open(plan);
  ASSERT_TRUE(approved.state().approval);
  EXPECT_EQ(approved.state().approval->by, "Dr Ada Lovelace");

  // The exported file changed on disk: verify fails.
  write_file_atomically(dir.path("signed.stl"), "not the implant");
  EXPECT_EQ(test::run_command(cli + " verify --json " + plan, &out), 4);
  EXPECT_NE(out.find("signed.stl (CHANGED on disk)"), std::string::npos) << out;

  // A change of the implant after the approval withdraws it.
  Session s = Session::open(plan);
  ImplantParams p = *s.state().implant_params;
  p.resolution_mm *= 1.5;
  const PushResult changed = s.push(commands::build_implant(p));
  ASSERT_TRUE(changed.accepted) << changed.message;
  EXPECT_FALSE(s.state().approval);
  EXPECT_NE(changed.message.find("approval withdrawn"), std::string::npos) << changed.message;
  s.save(plan);
  EXPECT_EQ(test::run_command(cli + " verify --json " + plan, &out), 4);
  EXPECT_NE(out.find("the implant changed after Dr Ada Lovelace approved it: not approved"),
            std::string::npos)
      << out;
  // Undone, the approval holds again (the implant is the approved one).
  s.undo();
  EXPECT_TRUE(s.state().approval);
  // An approval of another implant's hash is refused.
  EXPECT_FALSE(s.push(commands::approve("Dr B", "neurosurgeon", std::string(64, 'a'))).accepted);
}

// The design report names what is signed: dimensions, quality, provenance (the skull's and the
// implant's SHA-256, the plan's hash), the pictures given, the approval or the lines to sign.
TEST(DesignReport, NamesTheImplantItsProvenanceAndItsSignOff) {
  Session s = Session::open(planned().session_path);
  std::string html = design_report_html(s, {{"Front", "r_front.png"}}, "9.9.9");
  for (const std::string& want :
       {std::string("Implant design report"), std::string("Not approved yet"),
        std::string("Extent (principal axes)"), std::string("Volume"), std::string("Printable"),
        std::string("<img src=\"r_front.png\""), std::string("Cranioplan 9.9.9"),
        s.state().implant->stl_sha256(), s.journal().back().hash,
        s.effective_commands().front().params["sha256"].get<std::string>()})
    EXPECT_NE(html.find(want), std::string::npos) << want;
  // The margin the implant was fitted to the bone with (the planned case's is fitted).
  const ImplantResult& built = s.state().implant->result();
  ASSERT_GT(built.fit_to_bone_used_mm, 0.0);
  char fitted[96];
  std::snprintf(fitted, sizeof(fitted), "Fitted to the bone</th><td>%.1f mm over it",
                built.fit_to_bone_used_mm);
  EXPECT_NE(html.find(fitted), std::string::npos) << fitted;
  push_ok(s, commands::approve("Dr <B>", "neurosurgeon"));
  html = design_report_html(s, {}, "9.9.9");
  EXPECT_NE(html.find("Approved</b> by Dr &lt;B&gt; (neurosurgeon)"), std::string::npos);
}

TEST(Audit, TimelineNamesWhoWhenWhatAndStepTimes) {
  const SessionDocument doc = read_session_document(planned().session_path);
  const std::string text = audit_text(doc);
  EXPECT_NE(text.find("expert"), std::string::npos);
  EXPECT_NE(text.find("Propose markers automatically"), std::string::npos);
  EXPECT_NE(text.find("Time per step"), std::string::npos);
  const std::string html = audit_html(doc);
  EXPECT_NE(html.find("<table>"), std::string::npos);
  const StepDurations d = step_durations(doc.header, doc.journal);
  double sum = 0;
  for (int s = 1; s <= 9; ++s) sum += d.seconds[s];
  EXPECT_NEAR(sum, d.total, 1e-9);
  EXPECT_GT(d.seconds[5], 0.0) << "proposing markers takes time";
}

TEST(Audit, StepDurationsFollowTheJournalTimes) {
  SessionHeader h;
  h.info.created = "2026-01-01T10:00:00.000Z";
  auto entry = [](const char* time, int step) {
    JournalEntry e;
    e.event = "do";
    e.time = time;
    Command c = commands::note("x");
    c.meta.step = step;
    e.command = c;
    return e;
  };
  const std::vector<JournalEntry> j = {
      entry("2026-01-01T10:01:00.000Z", 1), entry("2026-01-01T10:03:30.000Z", 2),
      entry("2026-01-01T10:03:40.500Z", 0), entry("2026-01-01T11:00:00.000Z", 5)};
  const StepDurations d = step_durations(h, j, 300);
  EXPECT_NEAR(d.seconds[1], 60, 1e-6);
  EXPECT_NEAR(d.seconds[2], 150 + 10.5, 1e-6) << "a note counts for the step before it";
  EXPECT_NEAR(d.seconds[5], 300, 1e-6) << "idle gaps are capped";
}

TEST(Training, ReportComparesTimesAndImplants) {
  const Session expert = Session::open(planned().session_path);
  // A trainee who planned the same case with a coarser implant.
  AutoplanParams coarse;
  coarse.implant.resolution_mm = 2.0;
  AutoplanSession trainee = autoplan_session(test::defect_skull_stl(), Landmarks{}, coarse, "",
                                             SessionInfo{"synthetic", "trainee", ""});
  ASSERT_TRUE(trainee.planned()) << trainee.message;
  const TrainingReport r = training_report(trainee.session, expert);
  ASSERT_TRUE(r.agreement);
  EXPECT_GT(r.agreement->dice, 0.9);
  EXPECT_LT(r.agreement->hd95_mm, 1.5);
  EXPECT_GT(r.reference_volume_mm3, 0);
  const std::string text = training_report_text(r);
  EXPECT_NE(text.find("trainee against expert"), std::string::npos) << text;
  EXPECT_NE(training_report_html(r).find("Implant agreement"), std::string::npos);
}

}  // namespace
}  // namespace cranioplan

namespace cranioplan {
namespace {

TEST(SessionCli, AutoplanWritesASessionThatAuditAndTrainingReportRead) {
  const std::string cli = CRANIOPLAN_CLI;
  const std::string session = test::scratch_path("cli_session.json");
  const std::string implant = test::scratch_path("cli_implant.stl");
  std::string out;
  ASSERT_EQ(test::run_command(cli + " autoplan " + test::defect_skull_stl() + " -o " + implant +
                                  " --session " + session + " --json",
                              &out),
            0)
      << out;
  const Json j = Json::parse(out);
  EXPECT_EQ(j["status"], "planned");
  EXPECT_EQ(j["session"], session);
  EXPECT_TRUE(j["quality"]["watertight"].get<bool>());
  EXPECT_EQ(test::validate_session_schema(session), "");
  EXPECT_EQ(test::run_command(cli + " verify " + session, &out), 0) << out;

  const std::string html = test::scratch_path("audit.html");
  ASSERT_EQ(test::run_command(cli + " audit " + session + " --html " + html, &out), 0);
  EXPECT_NE(out.find("Time per step"), std::string::npos) << out;
  EXPECT_NE(test::read_bytes(html).find("hash chain: holds"), std::string::npos);

  const std::string report = test::scratch_path("training.html");
  ASSERT_EQ(test::run_command(cli + " training-report " + session + " --reference " +
                                  planned().session_path + " --html " + report + " --json",
                              &out),
            0)
      << out;
  const Json t = Json::parse(out);
  EXPECT_GT(t["agreement"]["dice"].get<double>(), 0.99) << "the same plan twice";
  EXPECT_NE(test::read_bytes(report).find("Implant agreement"), std::string::npos);

  std::string missing_out;
  EXPECT_EQ(test::run_command(cli + " replay " + test::scratch_path("nope.json"), &missing_out), 3);
}

}  // namespace
}  // namespace cranioplan

namespace cranioplan {
namespace {

// The quality report's HTML (the wizard's Quality panel): every figure at its precision, the
// verdict, and the reasons escaped.
TEST(QualityHtml, ShowsEveryFigureAndEscapesTheReasons) {
  QualityReport r;
  r.printable = false;
  r.watertight = true;
  r.manifold = false;
  r.outward = true;
  r.self_intersections = 3;
  r.pieces = 2;
  r.volume_mm3 = 5866.65;
  r.area_mm2 = 3487.4;
  r.thickness_min_mm = 0.04;
  r.thickness_median_mm = 4.02;
  r.thickness_max_mm = 10.06;
  r.thin_volume_mm3 = 104.33;
  r.taper_reach_mm = 1.46;
  r.corner_reach_mm = 0.31;
  r.rim_gap_mm = 0.0895;
  r.penetration_mm3 = 0.04;
  r.reasons = {"gap of 1.2 mm < the rim & \"more\""};
  const std::string h = quality_report_html(r);
  for (const char* part :
       {"<td>Printable</td><td><b>NO</b>", "<td>Manifold</td><td><b><b>no</b></b>",
        "<td>Self-intersections</td><td><b>3</b>", "<td>Volume</td><td><b>5867 mm³</b>",
        "<td>Area</td><td><b>3487 mm²</b>", "<b>4.0 / 10.1 mm (0.0 at the tapered edge)</b>",
        "104.3 mm³: edge on the bone 1.5 mm wide, elsewhere 0.3 mm", "<b>0.09 mm</b>",
        "<td>Overlap with skull</td><td><b>0.0 mm³</b>",
        "<li>gap of 1.2 mm &lt; the rim &amp; &quot;more&quot;</li>"})
    EXPECT_NE(h.find(part), std::string::npos) << part << "\n" << h;
  r.taper_reach_mm = -1.0;
  r.rim_gap_mm = -1.0;
  r.penetration_mm3 = -1.0;
  r.reasons.clear();
  const std::string without = quality_report_html(r);
  EXPECT_NE(without.find("<td>Thinner than the minimum</td><td><b>everywhere</b>"),
            std::string::npos);
  EXPECT_EQ(without.find("Gap to bone"), std::string::npos) << "not measured, not shown";
  EXPECT_EQ(without.find("Problems"), std::string::npos);
  EXPECT_EQ(without.find("scan ended"), std::string::npos);
  // A defect that ran into the scan's end: the table and the verdict say the implant ends
  // there and the bone beyond is unknown, printable or not.
  r.ends_at_scan_end = true;
  EXPECT_NE(quality_report_html(r).find(
                "<td>Ends where the scan ended</td><td><b>yes: the bone beyond is unknown"),
            std::string::npos);
  for (bool printable : {true, false}) {
    r.printable = printable;
    const std::string v = quality_verdict_html(r, ImplantParams{});
    EXPECT_NE(v.find("The implant ends where the scan ended:</b> the defect runs into the border "
                     "of the scan, and the bone beyond it is unknown"),
              std::string::npos)
        << v;
    EXPECT_NE(v.find(printable ? "Printable" : "Not printable"), std::string::npos) << v;
  }
}

// The soft tissue in the implant's place: brain or dura reaching into the defect is the finding
// (red); a scalp sunk into an old defect is said apart, without alarm; the rows say what each
// figure is of, so that none reads as contradicting another.
TEST(QualityHtml, TellsTheBrainsSideFromASunkenScalp) {
  QualityReport r;
  r.printable = true;
  SoftTissueCheck sunken;
  sunken.checked = true;
  sunken.sunken_scalp_mm3 = 1882;
  sunken.closest_mm = 3.4;
  sunken.message =
      "soft tissue lies 3.4 mm under the implant's inner surface; 1882 mm³ of it are "
      "scalp sunk into the defect, which the implant lifts";
  const std::string calm = quality_report_html(r, &sunken);
  EXPECT_EQ(calm.find("color:#a00"), std::string::npos) << "no alarm for a sunken scalp\n" << calm;
  EXPECT_NE(calm.find("Sunken scalp in its place (lifted by it)</td><td><b>1882 mm³"),
            std::string::npos)
      << calm;
  EXPECT_NE(calm.find("Free space under the inner surface</td><td><b>3.4 mm to soft tissue"),
            std::string::npos)
      << calm;
  SoftTissueCheck bulging;
  bulging.checked = true;
  bulging.intrusion_mm3 = 640;
  bulging.intrusion_reach_mm = 3.5;
  bulging.finding = true;
  bulging.closest_mm = 0.0;
  bulging.message = "640 mm³ of the implant's inner half lie where the CT shows soft tissue";
  const std::string alarm = quality_report_html(r, &bulging);
  EXPECT_NE(alarm.find("color:#a00"), std::string::npos);
  EXPECT_NE(alarm.find("640 mm³, up to 3.5 mm above its inner surface"), std::string::npos);
  // Within the tolerance (the dura, the CT's partial volume): said, without alarm.
  bulging.intrusion_reach_mm = 1.2;
  bulging.finding = false;
  EXPECT_EQ(quality_report_html(r, &bulging).find("color:#a00"), std::string::npos);
  EXPECT_NE(alarm.find("Free space under the inner surface</td><td><b>none (tissue reaches"),
            std::string::npos)
      << alarm;
}

// A refused implant's verdict names what is wrong and what to try, in the wizard's words: the
// fit to the bone when it is off, the markers when it is on already; none for a printable one.
TEST(QualityAdvice, SaysWhatToTryForWhatIsWrong) {
  QualityReport r;
  r.printable = false;
  r.watertight = r.manifold = r.outward = true;
  r.self_intersections = 9;
  r.rim_gap_mm = 2.73;
  r.penetration_mm3 = 177;
  r.taper_reach_mm = 0.5;
  r.reasons = {"9 pairs of triangles cross each other",
               "gap of 2.73 mm between the rim and the bone (limit 1.00 mm)"};
  ImplantParams unfitted;
  const std::vector<std::string> fit = quality_advice(r, unfitted);
  ASSERT_EQ(fit.size(), 1u);
  EXPECT_NE(fit[0].find("\"Fit to the bone\" to 4 mm"), std::string::npos) << fit[0];
  ImplantParams fitted;
  fitted.fit_to_bone_mm = 4.0;
  const std::vector<std::string> markers = quality_advice(r, fitted);
  ASSERT_EQ(markers.size(), 3u);
  EXPECT_NE(markers[0].find("edge markers"), std::string::npos) << markers[0];
  EXPECT_NE(markers[2].find("smooth the markers (step 8)"), std::string::npos) << markers[2];
  const std::string verdict = quality_verdict_html(r, unfitted);
  EXPECT_NE(verdict.find("Not printable"), std::string::npos);
  EXPECT_NE(verdict.find("<li>9 pairs of triangles cross each other</li>"), std::string::npos);
  EXPECT_NE(verdict.find("What to try"), std::string::npos);
  r.printable = true;
  EXPECT_TRUE(quality_advice(r, unfitted).empty());
  EXPECT_NE(quality_verdict_html(r, unfitted).find("Printable"), std::string::npos);
}

}  // namespace
}  // namespace cranioplan
