#include "tracker/core/motion_model.h"

#include <sstream>

namespace vtrack {

const char* ToString(ModelKind kind) {
  switch (kind) {
    case ModelKind::kIsm:
      return "ISM";
    case ModelKind::kVasm:
      return "VASM";
  }
  return "unknown";
}

namespace internal {

bool CheckParam(bool ok, const char* params, const char* field, double value, const char* unit,
                const char* requirement, std::string* error) {
  if (ok) return true;
  if (error != nullptr) {
    std::ostringstream os;
    os.precision(10);
    os << params << "." << field << " = " << value << " " << unit << ": must be " << requirement;
    *error = os.str();
  }
  return false;
}

}  // namespace internal
}  // namespace vtrack
