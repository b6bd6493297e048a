#pragma once
// Tier-3 errors of sessions: a session file that cannot be used as it stands (not JSON, unknown
// schema version or command type, missing parameter, changed input, broken hash chain).
#include <string>

#include "cranioplan/model/error.h"

namespace cranioplan {

/// The message starts with the file (or "session" for one in memory) and says what is wrong,
/// e.g. "plan.json: journal entry 12 does not match the hash recorded in entry 13".
class SessionError : public InputError {
 public:
  using InputError::InputError;
};

}  // namespace cranioplan
