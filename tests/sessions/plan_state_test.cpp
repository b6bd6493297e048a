#include "cranioplan/sessions/plan_state.h"

#include <gtest/gtest.h>

#include "cranioplan/model/error.h"
#include "cranioplan/sessions/sha256.h"
#include "support/session_cases.h"

namespace cranioplan {
namespace {

void add_markers(PlanState& s, MarkerType type, int n) {
  for (int i = 0; i < n; ++i) s.markers.push_back(Marker{s.next_marker_id++, type, {}});
}

TEST(PlanState, TheNineStepsAreNumberedAndEachSaysWhenItIsDone) {
  ASSERT_EQ(wizard_steps().size(), 9u);
  for (int i = 0; i < 9; ++i) {
    EXPECT_EQ(wizard_steps()[i].number, i + 1);
    EXPECT_NE(std::string(wizard_steps()[i].instructions).find("Done"), std::string::npos) << i;
  }
  std::string missing;
  EXPECT_FALSE(step_complete(PlanState{}, 10, &missing));
  EXPECT_EQ(missing, "there is no step 10");
}

TEST(PlanState, MarkerStepsCountTheirMarkers) {
  PlanState s;
  std::string missing;
  add_markers(s, MarkerType::OuterEdge, 2);
  EXPECT_FALSE(step_complete(s, 5, &missing));
  EXPECT_EQ(missing, "place at least 3 outer edge markers (2 so far)");
  add_markers(s, MarkerType::OuterEdge, 1);
  EXPECT_TRUE(step_complete(s, 5));
  // Inner edge markers: none, or at least three.
  add_markers(s, MarkerType::InnerEdge, 2);
  EXPECT_FALSE(step_complete(s, 5, &missing));
  EXPECT_NE(missing.find("inner edge markers: 2 placed"), std::string::npos) << missing;
  add_markers(s, MarkerType::InnerEdge, 1);
  EXPECT_TRUE(step_complete(s, 5));
  // Step 6 counts outer surface markers only.
  add_markers(s, MarkerType::InnerSurface, 5);
  EXPECT_FALSE(step_complete(s, 6, &missing));
  EXPECT_EQ(missing, "place at least 3 outer surface markers (0 so far)");
  add_markers(s, MarkerType::OuterSurface, 3);
  EXPECT_TRUE(step_complete(s, 6));
  ASSERT_NE(s.find_marker(4), nullptr);
  EXPECT_EQ(s.find_marker(4)->type, MarkerType::InnerEdge);
  EXPECT_EQ(s.find_marker(99), nullptr);
}

TEST(PlanState, AStepIsLockedByTheFirstStepBeforeItThatIsNotDone) {
  PlanState s;
  std::string why;
  EXPECT_TRUE(step_unlocked(s, 1));
  EXPECT_FALSE(step_unlocked(s, 3, &why));
  EXPECT_EQ(why,
            "step 3 (Mirror and register) is locked: step 1 (Load skull) is not done — load a "
            "skull");
  s.acknowledged[4] = true;  // a later step done by hand does not unlock an earlier one
  EXPECT_FALSE(step_unlocked(s, 5));
}

TEST(PlanState, ApplyingACommandLeavesTheStateBeforeItAsItWas) {
  const PlanState empty;
  // A marker before any skull: refused, the state unchanged.
  const ApplyOutcome refused =
      apply_command(empty, commands::add_marker(MarkerType::OuterEdge, {1, 2, 3}));
  EXPECT_FALSE(refused.accepted);
  EXPECT_NE(refused.message.find("is locked"), std::string::npos) << refused.message;
  EXPECT_TRUE(refused.state.markers.empty());

  // A load names the file's SHA-256 (a session fills it in when the command is pushed).
  const std::string skull = test::small_skull_stl();
  EXPECT_THROW(apply_command(empty, commands::load_skull(skull)), InputError);
  const ApplyOutcome loaded =
      apply_command(empty, commands::load_skull(skull, {}, sha256_file(skull)));
  ASSERT_TRUE(loaded.accepted) << loaded.message;
  EXPECT_TRUE(step_complete(loaded.state, 1));
  EXPECT_FALSE(empty.skull) << "the state before is not changed";
  EXPECT_EQ(loaded.state.current_step, 2) << "the wizard moves on";
  // The reader's report is recorded (a replay checks the same file came in the same way).
  EXPECT_TRUE(loaded.record.contains("input_report")) << loaded.record.dump();

  // What each command belongs to: markers by their type, notes to no step.
  EXPECT_EQ(command_step(loaded.state, commands::add_marker(MarkerType::InnerEdge, {})), 5);
  EXPECT_EQ(command_step(loaded.state, commands::add_marker(MarkerType::OuterSurface, {})), 6);
  EXPECT_EQ(command_step(loaded.state, commands::note("x")), 0);
  EXPECT_EQ(command_step(loaded.state, commands::fit_plane()), 2);

  // A landmark goes onto the skull; one far from it (another frame) is refused.
  const Eigen::Vector3d top = loaded.state.skull->surface->locator.closest({0, 0, 500}).point;
  const ApplyOutcome near = apply_command(
      loaded.state, commands::set_landmark("nasion", top + Eigen::Vector3d(0, 0, 12)));
  ASSERT_TRUE(near.accepted) << near.message;
  EXPECT_LT(loaded.state.skull->surface->locator.closest(*near.state.landmarks.nasion).distance,
            1e-9)
      << "put on the surface";
  const ApplyOutcome far = apply_command(
      loaded.state, commands::set_landmark("nasion", top + Eigen::Vector3d(0, 0, 40)));
  EXPECT_FALSE(far.accepted);
  EXPECT_NE(far.message.find("the nasion landmark lies 4"), std::string::npos) << far.message;
  EXPECT_NE(far.message.find("mm from the skull (at most 25 mm): is it in the skull's frame?"),
            std::string::npos)
      << far.message;
}

TEST(PlanState, TheMirrorIsMovedByTheRegistrationThenByHand) {
  PlanState s;
  RegisterResult reg;
  reg.status = RegisterResult::Status::Converged;
  reg.transform = RigidTransform::from_axis_angle({0, 0, 1}, 90, {0, 0, 0});
  s.registration = reg;
  s.manual = RigidTransform::from_axis_angle({0, 0, 1}, 0, {5, 0, 0});
  // (1,0,0) turned to (0,1,0) by the registration, then moved 5 mm by hand.
  EXPECT_LT((s.mirror_transform().apply({1, 0, 0}) - Eigen::Vector3d(5, 1, 0)).norm(), 1e-12);
  // A failed registration does not move the mirror.
  s.registration->status = RegisterResult::Status::Failed;
  EXPECT_LT((s.mirror_transform().apply({1, 0, 0}) - Eigen::Vector3d(6, 0, 0)).norm(), 1e-12);
}

}  // namespace
}  // namespace cranioplan
