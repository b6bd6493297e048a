#include "cranioplan/model/param_spec.h"

#include <cmath>
#include <cstdio>

#include "cranioplan/model/error.h"

namespace cranioplan {
namespace {

// A bound as a person reads it: "0.05", "12", "100,000".
std::string bound(double v) {
  if (std::abs(v) >= 1e4 && std::abs(v) < 1e15 && v == std::round(v))
    return format_count(static_cast<long long>(v));
  char buf[40];
  std::snprintf(buf, sizeof(buf), "%g", v);
  return buf;
}

}  // namespace

bool ParamSpec::allows(double v) const {
  if (std::isnan(v)) return unset_allowed;
  if (zero_means_none && v == 0.0) return true;
  return std::isfinite(v) && v >= min && v <= max;
}

std::string ParamSpec::range_text() const {
  return std::string(zero_means_none ? "0, or " : "") + bound(min) + " to " + bound(max) +
         (*unit ? std::string(" ") + unit : std::string());
}

std::string ParamSpec::problem(const char* whose, double v) const {
  return problem(whose, v, min, max);
}

std::string ParamSpec::problem(const char* whose, double v, double lo, double hi) const {
  ParamSpec bounds = *this;
  bounds.min = lo;
  bounds.max = hi;
  return std::string(whose) + " " + (noun ? noun : key) + " must be " + bounds.range_text() + " (" +
         bound(v) + " given)";
}

}  // namespace cranioplan
