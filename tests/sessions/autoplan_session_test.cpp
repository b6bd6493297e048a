#include "cranioplan/sessions/autoplan_session.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>

#include "cranioplan/algorithms/io/load_skull.h"
#include "cranioplan/algorithms/io/write_mesh.h"
#include "cranioplan/algorithms/planning/autoplan.h"
#include "cranioplan/algorithms/shape/correspond_skull.h"
#include "cranioplan/algorithms/shape/shape_model.h"
#include "cranioplan/sessions/audit.h"
#include "cranioplan/sessions/marker_files.h"
#include "cranioplan/sessions/sha256.h"
#include "support/session_cases.h"
#include "support/synthetic.h"

namespace cranioplan {
namespace {

using test::PlannedCase;

const PlannedCase& planned() { return test::planned_defect_case(); }

TEST(AutoplanSession, GivesTheSameImplantAsAutoplan) {
  const PlannedCase& c = planned();
  const AutoplanResult direct = autoplan(load_skull(test::defect_skull_stl()).mesh, Landmarks{});
  ASSERT_TRUE(direct.planned());
  EXPECT_EQ(sha256_hex(encode_mesh(direct.implant.mesh, MeshFormat::BinarySTL)), c.implant_sha);
  EXPECT_EQ(test::validate_session_schema(c.session_path), "");
}

TEST(AutoplanSession, ReplayReproducesTheExportByteForByte) {
  const PlannedCase& c = planned();
  const Session replayed = Session::open(c.session_path);
  ASSERT_TRUE(replayed.state().implant);
  EXPECT_EQ(replayed.state().implant->stl_sha256(), c.implant_sha);
  for (int step = 1; step <= 9; ++step) EXPECT_TRUE(step_complete(replayed.state(), step)) << step;
  const VerifyReport v = verify_session(c.session_path);
  EXPECT_TRUE(v.ok());
  for (const auto& check : v.checks) EXPECT_TRUE(check.ok) << check.name << ": " << check.detail;
}

// A plan guided by a shape model records the model as an input (its path and SHA-256) with the
// proposal: the session replays to the same implant without reading it again, and verify checks
// the model's bytes like the skull's. The model here is a small one made of the case's intact
// head stretched three ways (what is tested is the recording, not the model's accuracy).
TEST(AutoplanSession, AShapeModelIsRecordedAsAnInputAndVerified) {
  const auto dir = std::filesystem::temp_directory_path() / "cranioplan_session_shape_model";
  std::filesystem::create_directories(dir);
  ShapeModel model = test::stretched_head_model(test::make_thick_head(0.93, 0.8));
  ASSERT_GT(model.outer_count, 100);
  model.provenance.skull_sha256 = {"a", "b", "c"};
  model.provenance.skull_names = {"a", "b", "c"};
  const std::string model_path = (dir / "skulls.cpsm").string();
  write_shape_model(model, model_path);

  const std::string session_path = (dir / "plan.json").string();
  AutoplanSession a = autoplan_session(test::defect_skull_stl(), Landmarks{}, AutoplanParams{},
                                       (dir / "implant.stl").string(), {}, {}, false, model_path);
  ASSERT_TRUE(a.planned()) << a.message;
  a.session.save(session_path);
  bool recorded = false;
  for (const auto& c : a.session.effective_commands())
    if (c.type == CommandType::ProposeMarkers) {
      ASSERT_TRUE(c.params.contains("shape_model"));
      EXPECT_EQ(c.params["shape_model"]["sha256"], sha256_file(model_path));
      // How the model was weighed, fitted and judged, so a re-proposal does the same.
      const ShapePriorParams prior;
      EXPECT_EQ(c.params["shape_model"]["weight"], ProposeParams{}.shape_model_weight);
      EXPECT_EQ(c.params["shape_model"]["margin_mm"], prior.margin_mm);
      EXPECT_EQ(c.params["shape_model"]["noise_mm"], prior.fit.noise_mm);
      EXPECT_EQ(c.params["shape_model"]["max_rms_mm"], prior.fit.max_rms_mm);
      EXPECT_EQ(c.params["shape_model"]["min_paired"], prior.fit.min_paired);
      EXPECT_NE(c.params["result"]["message"].get<std::string>().find("shape model"),
                std::string::npos);
      recorded = true;
    }
  EXPECT_TRUE(recorded);
  EXPECT_EQ(test::validate_session_schema(session_path), "");
  const std::string implant_sha = a.session.state().implant->stl_sha256();
  // Reopened, the plan knows which model its proposal named (the wizard shows it so).
  const Session reopened = Session::open(session_path);
  EXPECT_EQ(reopened.state().implant->stl_sha256(), implant_sha);
  EXPECT_EQ(reopened.state().proposal_shape_model, model_path);
  EXPECT_TRUE(verify_session(session_path).ok());

  // Proposed again from the command alone, guided by the model throughout (method model): the
  // recorded weight is the one used, and a version-7 command (none recorded) is read with the
  // 0.5 it was made with.
  {
    Session s = Session::open(session_path);
    const auto at = test::first_command(s, CommandType::ProposeMarkers);
    ASSERT_TRUE(at);
    Command fresh = s.effective_commands()[*at];
    fresh.params.erase("result");
    fresh.params["params"]["method"] = "model";
    auto markers_of = [&](const Command& c) {
      const ApplyOutcome out = apply_command(s.state_at(*at), c);
      EXPECT_TRUE(out.accepted) << out.message;
      return out.record["result"]["markers"];
    };
    Command half = fresh, whole = fresh, seven = fresh;
    half.params["shape_model"]["weight"] = 0.5;
    whole.params["shape_model"]["weight"] = 1.0;
    seven.version = 7;
    for (const char* recorded_since_8 :
         {"weight", "margin_mm", "noise_mm", "max_rms_mm", "min_paired"})
      seven.params["shape_model"].erase(recorded_since_8);
    const Json by_half = markers_of(half);
    EXPECT_EQ(markers_of(seven), by_half);
    EXPECT_NE(markers_of(whole), by_half);
    // The plan keeps what its proposal was asked (the wizard proposes again with it), read from
    // the recorded command without the model's file.
    Command recorded = s.effective_commands()[*at];
    recorded.params["shape_model"]["weight"] = 0.75;
    recorded.params["shape_model"]["margin_mm"] = 12.0;
    recorded.params["params"]["surface_spacing_mm"] = 5.0;
    const ApplyOutcome out = apply_command(s.state_at(*at), recorded);
    ASSERT_TRUE(out.accepted) << out.message;
    EXPECT_EQ(out.state.proposal_params.shape_model_weight, 0.75);
    EXPECT_EQ(out.state.proposal_params.surface_spacing_mm, 5.0);
    EXPECT_EQ(out.state.proposal_prior.margin_mm, 12.0);
    EXPECT_EQ(out.state.proposal_prior.fit.noise_mm, ShapePriorParams{}.fit.noise_mm);
    // A proposal of an earlier version (read with the switches that replay it as it was made:
    // the rays' rim, support markers on every layer) is made again with today's parameters and
    // its model's weight.
    Command older = recorded;
    older.version = 7;
    older.params["params"]["detect"].erase("trace_rim_on_bone");
    older.params["params"].erase("max_support_layers");
    const ApplyOutcome old_out = apply_command(s.state_at(*at), older);
    ASSERT_TRUE(old_out.accepted) << old_out.message;
    EXPECT_TRUE(old_out.state.proposal_params.detect.trace_rim_on_bone);
    EXPECT_EQ(old_out.state.proposal_params.max_support_layers, ProposeParams{}.max_support_layers);
    EXPECT_EQ(old_out.state.proposal_params.surface_spacing_mm, ProposeParams{}.surface_spacing_mm);
    EXPECT_EQ(old_out.state.proposal_params.shape_model_weight, 0.75);
  }

  // The model changed after the plan: verify says so, naming it.
  std::ofstream(model_path, std::ios::app) << "x";
  const VerifyReport v = verify_session(session_path);
  EXPECT_FALSE(v.ok());
  bool named = false;
  for (const auto& check : v.checks)
    if (check.name == "inputs")
      named = check.detail.find("shape model changed") != std::string::npos;
  EXPECT_TRUE(named);
  std::filesystem::remove_all(dir);
}

// A skull from 3D Slicer in RAS (SPACE=RAS) is planned in the patient's LPS and its implant
// exported back in the file's RAS, saying so: it lies in the defect of the file as given, in
// Slicer and in any program that reads coordinates as they are. Here the synthetic case's
// skull is written in RAS: read back into LPS it is the same skull, so the plan is the same,
// and the export is the same implant, x and y negated, its STL header declaring RAS.
TEST(AutoplanSession, AnImplantPlannedOnARasSkullIsExportedInRas) {
  const PlannedCase& c = planned();
  const std::string ras_skull = test::scratch_path("defect_ras.stl");
  const std::string ras_implant = test::scratch_path("defect_ras_implant.stl");
  write_mesh(load_skull(test::defect_skull_stl()).mesh, ras_skull, MeshSpace::RAS);
  AutoplanSession a = autoplan_session(ras_skull, Landmarks{}, AutoplanParams{}, ras_implant,
                                       SessionInfo{"synthetic", "expert", ""});
  ASSERT_TRUE(a.planned()) << a.message;
  // Both in the files' order (the canonical order depends on the coordinates).
  ExtractBoneSurfaceParams raw;
  raw.canonical = false;
  const LoadedSkull lps_implant = load_surface(c.implant_path, raw);
  raw.mesh_space_from_header = false;
  const LoadedSkull as_written = load_surface(ras_implant, raw);
  ASSERT_EQ(as_written.mesh.n_vertices(), lps_implant.mesh.n_vertices());
  double off = 0.0;
  for (auto vh : lps_implant.mesh.vertices()) {
    const auto& p = lps_implant.mesh.point(vh);
    const auto& q = as_written.mesh.point(SkullMesh::VertexHandle(vh.idx()));
    off = std::max(off, (Eigen::Vector3d(-p[0], -p[1], p[2]) - to_eigen(q)).norm());
  }
  EXPECT_LT(off, 1e-5) << "the same implant, in RAS";
  EXPECT_EQ(load_surface(ras_implant).file_space, MeshSpace::RAS);
  EXPECT_EQ(a.session.state().implant->stl_sha256(), sha256_file(ras_implant))
      << "the implant's STL checksum is the exported file's";
  // Reopened, the plan replays to the same bytes.
  const std::string session = test::scratch_path("defect_ras.json");
  a.session.save(session);
  const VerifyReport v = verify_session(session);
  for (const auto& check : v.checks) EXPECT_TRUE(check.ok) << check.name << ": " << check.detail;
}

// The proposal is recorded in its command (what a replay applies): the markers, with their
// ids, are those of the plan.
TEST(AutoplanSession, TheProposalIsRecordedInItsCommand) {
  const Session s = Session::open(planned().session_path);
  const auto at = test::first_command(s, CommandType::ProposeMarkers);
  ASSERT_TRUE(at);
  const Command propose = s.effective_commands()[*at];
  EXPECT_EQ(propose.version, 8);
  ASSERT_TRUE(propose.params.contains("result"));
  const Json& result = propose.params["result"];
  EXPECT_EQ(result["proposed"], true);
  EXPECT_EQ(result["markers"], markers_to_json(s.state().markers)["markers"]);
  EXPECT_EQ(result["message"], s.state().proposal_message);
  ASSERT_TRUE(s.state().defect_center);
  EXPECT_EQ(result["defect_center"], to_json(*s.state().defect_center));
  // autoplan_session proposed for the opening it had found; the command alone, on the state
  // before it, finds and proposes the same.
  Session again = Session::open(planned().session_path);
  Command fresh = propose;
  fresh.params.erase("result");
  const ApplyOutcome out = apply_command(again.state_at(*at), fresh);
  ASSERT_TRUE(out.accepted) << out.message;
  EXPECT_EQ(out.record["result"], result);
}

TEST(AutoplanSession, UndoOfTheLastCommandUsesTheCache) {
  Session s = Session::open(planned().session_path);
  const size_t n = s.index();
  ASSERT_TRUE(s.undo());
  EXPECT_EQ(s.index(), n - 1);
  ASSERT_TRUE(s.undo());  // export, review: the implant is still there
  EXPECT_TRUE(s.state().implant);
  ASSERT_TRUE(s.redo());
  ASSERT_TRUE(s.redo());
  EXPECT_EQ(s.state().implant->stl_sha256(), planned().implant_sha);
}

}  // namespace
}  // namespace cranioplan

namespace cranioplan {
namespace {

// The wizard's manual path with every page's defaults — the commands its buttons push: Fit
// plane, Done, Mirror, Register, Done, Done (step 4), Propose markers, Done, Done, Build implant
// with step 7's defaults (the automatic plan's fit to the bone) — ends printable on SkullFix's
// five cases (../shared/data/skullfix; skipped without it).
TEST(ManualPath, TheWizardsDefaultsEndPrintableOnSkullFix) {
  const std::string dir = CRANIOPLAN_SKULLFIX_DIR;
  if (!std::filesystem::exists(dir + "/000_defective_skull.nrrd"))
    GTEST_SKIP() << "SkullFix data not present";
  for (int k = 0; k < 5; ++k) {
    char name[64];
    std::snprintf(name, sizeof(name), "%03d_defective_skull.nrrd", k);
    Session s(SessionInfo{name, "", ""});
    // Step 1's threshold field is automatic by default (a mask: 0.5).
    test::push_ok(s, commands::load_skull(dir + "/" + name, ExtractBoneSurfaceParams{}));
    for (Command c : {commands::fit_plane(), commands::complete_step(2), commands::mirror(),
                      commands::register_mirror(RegisterParams{}), commands::complete_step(3),
                      commands::complete_step(4), commands::propose_markers(ProposeParams{}),
                      commands::complete_step(5), commands::complete_step(6),
                      commands::build_implant(AutoplanParams{}.implant)})
      test::push_ok(s, std::move(c));
    ASSERT_TRUE(s.state().implant) << name << ": " << s.state().message;
    const QualityReport& q = s.state().implant->quality();
    RecordProperty(std::string(name, 3) + "_rim_gap_mm", std::to_string(q.rim_gap_mm));
    EXPECT_TRUE(q.printable) << name << ": "
                             << (q.reasons.empty() ? std::string() : q.reasons.front());
  }
}

}  // namespace
}  // namespace cranioplan
