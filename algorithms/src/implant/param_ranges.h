#pragma once
// The range checks of the implant operations' parameters (holes, tabs, mould), and the sentence
// that names a value out of its range.
#include <cmath>
#include <cstdio>
#include <string>

namespace cranioplan {

/// Whether `v` is a number from `lo` to `hi`.
inline bool within(double v, double lo, double hi) {
  return std::isfinite(v) && v >= lo && v <= hi;
}

/// "the holes' diameter must be 1 to 6 mm (7 given)": `whose` names what the parameter is of.
inline std::string parameter_range_problem(const char* whose, const char* what, double v, double lo,
                                           double hi) {
  char buf[200];
  std::snprintf(buf, sizeof(buf), "%s %s must be %g to %g mm (%g given)", whose, what, lo, hi, v);
  return buf;
}

}  // namespace cranioplan
