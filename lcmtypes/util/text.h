// Text helpers shared by the processes: printf-style formatting into a string and lists of
// numbers given on the command line.
#pragma once

#include <optional>
#include <string>
#include <vector>

namespace vtrack::lcm_util {

// printf into a string; the result is cut at 511 characters.
std::string Format(const char* fmt, ...) __attribute__((format(printf, 1, 2)));

// Splits text at separator and reads each piece as a number that fills the whole piece
// (std::stod). Returns the numbers, or nullopt with the first piece that is not a number (or,
// with finite_only, not a finite one) in *bad. Empty text gives an empty list.
std::optional<std::vector<double>> ParseNumberList(const std::string& text, char separator,
                                                   bool finite_only, std::string* bad);

}  // namespace vtrack::lcm_util
