#include "cranioplan/sessions/previews.h"

#include "cranioplan/algorithms/implant/build_implant.h"
#include "cranioplan/model/error.h"

namespace cranioplan {

std::shared_ptr<const PlanState> preview_command(const PlanState& state, const Command& command,
                                                 const ApplyContext& context) {
  try {
    ApplyOutcome out = apply_command(state, command, context);
    if (!out.accepted) return nullptr;
    return std::make_shared<const PlanState>(std::move(out.state));
  } catch (const Error&) {
    return nullptr;
  }
}

std::shared_ptr<const PlanState> preview_command_quickly(const PlanState& state,
                                                         const Command& command,
                                                         const ApplyContext& context) {
  if (!state.implant_params) return preview_command(state, command, context);
  PlanState quick = state;
  quick.implant_params = live_preview_params(*state.implant_params);
  return preview_command(quick, command, context);
}

}  // namespace cranioplan
