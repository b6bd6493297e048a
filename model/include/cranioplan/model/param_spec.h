#pragma once
// A parameter of an operation declared once: its name in a session's JSON, the words a message
// uses for it, its range and unit, its command-line option and its help. Each Params struct
// lists its fields with their declarations in one `for_each_field(visit, params)` next to the
// struct; the session's JSON, the CLI's options, the GUI's fields and the range checks are all
// made from that list (docs/ARCHITECTURE.md "Parameters").
#include <cassert>
#include <cstring>
#include <string>
#include <type_traits>

namespace cranioplan {

struct ParamSpec {
  const char* key = "";          ///< its field in a session's JSON: "wall_mm"
  const char* noun = nullptr;    ///< in a message, after whose it is: "wall"; nullptr: not ranged
  double min = 0.0, max = 0.0;   ///< the values allowed, both included
  const char* unit = "";         ///< "mm", or "" for a count
  const char* option = nullptr;  ///< its command-line option without "--"; nullptr: none
  const char* help = "";         ///< what it is: the option's help, the GUI field's tooltip
  bool unset_allowed = false;    ///< NaN allowed: the value is then derived (from the material)
  bool zero_means_none = false;  ///< 0 allowed below the range: none (no countersink, no onlay)

  bool ranged() const { return noun != nullptr; }
  /// Whether `v` may be given: NaN where unset is allowed, else a number in the range.
  bool allows(double v) const;
  /// "the holes' diameter must be 1 to 6 mm (8 given)"; `whose`: "the holes'".
  std::string problem(const char* whose, double v) const;
  /// The same sentence for a bound that depends on another parameter ("the holes' spacing must
  /// be 4 to 40 mm" where 4 is twice the diameter).
  std::string problem(const char* whose, double v, double lo, double hi) const;

  ParamSpec with_option(const char* name, const char* text) const {
    ParamSpec s = *this;
    s.option = name;
    s.help = text;
    return s;
  }
  ParamSpec unset_derived() const {
    ParamSpec s = *this;
    s.unset_allowed = true;
    return s;
  }
  ParamSpec zero_for_none() const {
    ParamSpec s = *this;
    s.zero_means_none = true;
    return s;
  }
  /// "1 to 6 mm", "0, or 3 to 20 mm": the values allowed, as a message says them.
  std::string range_text() const;
};

/// A length in mm from `lo` to `hi`.
inline ParamSpec length_mm(const char* key, const char* noun, double lo, double hi) {
  return ParamSpec{key, noun, lo, hi, "mm"};
}
/// A number without a unit (a count, a fraction) from `lo` to `hi`.
inline ParamSpec number(const char* key, const char* noun, double lo, double hi) {
  return ParamSpec{key, noun, lo, hi, ""};
}
/// An angle in degrees from `lo` to `hi`.
inline ParamSpec angle_deg(const char* key, const char* noun, double lo, double hi) {
  return ParamSpec{key, noun, lo, hi, "deg"};
}
/// A field without a range: a flag, a list of points, an optional plane.
inline ParamSpec field(const char* key) { return ParamSpec{key}; }

/// The declaration of `P`'s field `key` (found through P's `for_each_field`).
template <class P>
ParamSpec spec_of(const char* key) {
  P p;
  ParamSpec out;
  for_each_field(
      [&](const ParamSpec& s, auto&) {
        if (std::strcmp(s.key, key) == 0) out = s;
      },
      p);
  assert(*out.key && "spec_of: P declares no field of that name");
  return out;
}

/// The first field of `p` whose value is outside its declared range, as a sentence ("the
/// holes' diameter must be 1 to 6 mm (8 given)"), or empty. Fields of other types (flags, lists)
/// are checked by the operation's own rules.
template <class P>
std::string range_problems(const char* whose, const P& p) {
  std::string problem;
  auto check = [&](const ParamSpec& s, const auto& value) {
    using T = std::decay_t<decltype(value)>;
    if constexpr (std::is_arithmetic_v<T> && !std::is_same_v<T, bool>) {
      if (problem.empty() && s.ranged() && !s.allows(static_cast<double>(value)))
        problem = s.problem(whose, static_cast<double>(value));
    }
  };
  for_each_field(check, const_cast<P&>(p));  // `check` only reads
  return problem;
}

}  // namespace cranioplan
