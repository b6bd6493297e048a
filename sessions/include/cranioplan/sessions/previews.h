#pragma once
// The state a command would give, without recording it: what a window shows while a control
// or a marker is being moved.
#include <memory>

#include "cranioplan/sessions/plan_state.h"

namespace cranioplan {

/// `command` applied to `state`; none when it is refused there or meets a bad input.
std::shared_ptr<const PlanState> preview_command(const PlanState& state, const Command& command,
                                                 const ApplyContext& context);

/// The same with the implant rebuilt as its quick preview (live_preview_params: the shell
/// without the fit to the bone and what needs it): for a marker while it is dragged.
std::shared_ptr<const PlanState> preview_command_quickly(const PlanState& state,
                                                         const Command& command,
                                                         const ApplyContext& context);

}  // namespace cranioplan
