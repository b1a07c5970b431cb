#include "lcmtypes/util/text.h"

#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <sstream>

namespace vtrack::lcm_util {

std::string Format(const char* fmt, ...) {
  char buf[512];
  va_list ap;
  va_start(ap, fmt);
  std::vsnprintf(buf, sizeof(buf), fmt, ap);
  va_end(ap);
  return buf;
}

std::optional<std::vector<double>> ParseNumberList(const std::string& text, char separator,
                                                   bool finite_only, std::string* bad) {
  std::vector<double> out;
  std::stringstream ss(text);
  std::string item;
  while (std::getline(ss, item, separator)) {
    std::size_t used = 0;
    double v = 0.0;
    try {
      v = std::stod(item, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used == 0 || used != item.size() || (finite_only && !std::isfinite(v))) {
      *bad = item;
      return std::nullopt;
    }
    out.push_back(v);
  }
  return out;
}

}  // namespace vtrack::lcm_util
