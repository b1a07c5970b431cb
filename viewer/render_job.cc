#include "viewer/render_job.h"

#include <cmath>
#include <sstream>

namespace vtrack::viewer {

std::string RenderJob::FirstProblem() const {
  for (const std::string& err : {channels.FirstProblem(), assembler.FirstProblem(),
                                 scene.FirstProblem(), render.FirstProblem()}) {
    if (!err.empty()) return err;
  }
  std::ostringstream os;
  if (!(start_s >= 0.0) || std::isinf(start_s)) {
    os << "start = " << start_s << ": must be finite and >= 0 s";
  } else if (!(end_s > start_s)) {
    os << "end = " << end_s << ": must be after start = " << start_s << " s";
  } else if (max_frames < 0) {
    os << "max_frames = " << max_frames << ": must be >= 0 (0 = no limit)";
  }
  return os.str();
}

}  // namespace vtrack::viewer
