#include "cranioplan/sessions/autoplan_session.h"

#include <gtest/gtest.h>

#include "cranioplan/algorithms/io/load_skull.h"
#include "cranioplan/algorithms/io/write_mesh.h"
#include "cranioplan/algorithms/planning/autoplan.h"
#include "cranioplan/sessions/audit.h"
#include "cranioplan/sessions/marker_files.h"
#include "cranioplan/sessions/sha256.h"
#include "support/session_cases.h"

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

// The proposal is recorded in its command (what a replay applies): the markers, with their
// ids, are those of the plan.
TEST(AutoplanSession, TheProposalIsRecordedInItsCommand) {
  const Session s = Session::open(planned().session_path);
  const auto at = test::first_command(s, CommandType::ProposeMarkers);
  ASSERT_TRUE(at);
  const Command propose = s.effective_commands()[*at];
  EXPECT_EQ(propose.version, 6);
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
