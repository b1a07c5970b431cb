// One declaration per parameter. Every Params struct of the core lists its fields once, in a
// member template Visit(V&), each with its YAML key, unit, valid range and a one-line reason; its
// default is the field's initialiser. That one list drives:
//   - validation (param::FirstProblem below: every range, then the struct's cross-field rules),
//   - YAML reading (tracker/config.cc: unknown, duplicate and ill-typed keys refused),
//   - the shipped config and the parameter reference (vtrack-tracker --print-config,
//     --print-parameter-reference; ctest parameters_current_test keeps both files current).
// Drake's Serialize(Archive*) is the model: a visitor over named fields, no reflection library.
#pragma once

#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <sstream>
#include <string>
#include <type_traits>
#include <vector>

#include "base/enum_names.h"

namespace vtrack::param {

// The valid values of a numeric field: an interval whose ends are open or closed; NaN never lies
// in it, and +-infinity only where an end is infinite and closed.
struct Range {
  double lo = -std::numeric_limits<double>::infinity();
  double hi = std::numeric_limits<double>::infinity();
  bool lo_open = false;
  bool hi_open = false;

  bool Contains(double v) const {
    if (std::isnan(v)) return false;
    const bool above = lo_open ? v > lo : v >= lo;
    const bool below = hi_open ? v < hi : v <= hi;
    return above && below;
  }
  // "in [0, 1)", ">= 0", "> 0", "<= 50" or "finite" (a bound at +-DBL_MAX only excludes infinity).
  std::string ToString() const {
    std::ostringstream os;
    os.precision(10);
    const bool has_lo = lo > std::numeric_limits<double>::lowest();
    const bool has_hi = hi < std::numeric_limits<double>::max();
    if (has_lo && has_hi) {
      os << "in " << (lo_open ? "(" : "[") << lo << ", " << hi << (hi_open ? ")" : "]");
    } else if (has_lo) {
      os << (lo_open ? "> " : ">= ") << lo;
    } else if (has_hi) {
      os << (hi_open ? "< " : "<= ") << hi;
    } else {
      os << (std::isinf(lo) || std::isinf(hi) ? "a number" : "finite");
    }
    return os.str();
  }
};

inline Range Any() { return {}; }
inline Range Finite() {
  return {std::numeric_limits<double>::lowest(), std::numeric_limits<double>::max(), false, false};
}
inline Range AtLeast(double lo) { return {lo, std::numeric_limits<double>::max(), false, false}; }
inline Range Above(double lo) { return {lo, std::numeric_limits<double>::max(), true, false}; }
inline Range AtMost(double hi) { return {std::numeric_limits<double>::lowest(), hi, false, false}; }
inline Range Closed(double lo, double hi) { return {lo, hi, false, false}; }
inline Range OpenClosed(double lo, double hi) { return {lo, hi, true, false}; }  // (lo, hi]
inline Range ClosedOpen(double lo, double hi) { return {lo, hi, false, true}; }  // [lo, hi)
inline Range Open(double lo, double hi) { return {lo, hi, true, true}; }

// What a field's declaration says besides its key and default.
struct Info {
  const char* unit;    // "m", "s", "deg", "-" (dimensionless), ...
  Range range;         // valid values (numbers); ignored for enumerations and lists
  const char* reason;  // one line: what it decides and why this value
};

// A struct with a parameter list: has Visit(V&) and a section name.
template <class P>
concept Declared = requires { P::kSection; };

// Formats a number as the YAML file and the reference show it.
template <class T>
std::string Format(T value) {
  std::ostringstream os;
  if constexpr (std::is_same_v<T, bool>) {
    os << (value ? "true" : "false");
  } else if constexpr (std::is_floating_point_v<T>) {
    os.precision(10);
    os << value;
    const std::string s = os.str();
    // A double always reads back as a number with a point, never as an integer.
    if (s.find_first_of(".eEn") == std::string::npos) os << ".0";
  } else {
    os << value;
  }
  return os.str();
}

// Collects the first field out of its range (depth first through lists of structs).
class RangeChecker {
 public:
  explicit RangeChecker(std::string prefix) : prefix_(std::move(prefix)) {}

  template <class T>
  void operator()(const char* key, T* value, const Info& info) {
    if (!problem_.empty()) return;
    if constexpr (std::is_arithmetic_v<T> && !std::is_same_v<T, bool>) {
      if (!info.range.Contains(static_cast<double>(*value))) {
        problem_ = prefix_ + key + " = " + Format(*value) + " " + info.unit + ": must be " +
                   info.range.ToString();
      }
    } else if constexpr (requires { value->front().Visit(*this); }) {
      for (std::size_t i = 0; i < value->size() && problem_.empty(); ++i) {
        RangeChecker nested(prefix_ + key + "[" + std::to_string(i) + "].");
        (*value)[i].Visit(nested);
        problem_ = nested.problem();
      }
    }
  }
  const std::string& problem() const { return problem_; }

 private:
  std::string prefix_;
  std::string problem_;
};

// "" if every field of p lies in its declared range and p's cross-field rules hold (a struct may
// declare `std::string CrossProblem() const`); else the first problem, naming section.key.
template <Declared P>
std::string FirstProblem(const P& p) {
  P copy = p;  // Visit takes mutable pointers (one list serves reading and checking)
  RangeChecker check(std::string(P::kSection) + ".");
  copy.Visit(check);
  if (!check.problem().empty()) return check.problem();
  if constexpr (requires { p.CrossProblem(); }) {
    const std::string cross = p.CrossProblem();
    if (!cross.empty()) return std::string(P::kSection) + "." + cross;
  }
  return {};
}

// True if valid; otherwise false and *error (if given) holds FirstProblem(p).
template <Declared P>
bool Validate(const P& p, std::string* error) {
  std::string e = FirstProblem(p);
  if (e.empty()) return true;
  if (error != nullptr) *error = std::move(e);
  return false;
}

// "key = value unit: must be requirement" for a cross-field rule of CrossProblem().
template <class T>
std::string Problem(const char* key, T value, const char* unit, const std::string& requirement) {
  return std::string(key) + " = " + Format(value) + " " + unit + ": must be " + requirement;
}

}  // namespace vtrack::param
