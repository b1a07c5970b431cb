#include "tracker/core/motion_model.h"

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

}  // namespace vtrack
