// What to render and how, shared by the offline (log) and live (bus) paths of vtrack-render.
#pragma once

#include <cstdint>
#include <limits>
#include <string>

#include "viewer/frame_assembler.h"
#include "viewer/message_router.h"
#include "viewer/renderer.h"
#include "viewer/scene_builder.h"
#include "viewer/validate.h"

namespace vtrack::viewer {

struct RenderJob {
  Channels channels;
  AssemblerParams assembler;
  SceneParams scene;
  RenderParams render;
  double start_s = 0.0;                                     // [s] frames earlier than this (since
                                                            //     the first frame) are skipped
  double end_s = std::numeric_limits<double>::infinity();   // [s] and later than this
  std::int64_t max_frames = 0;                              // [-] stop after this many; 0 = all

  // True if every field is valid; otherwise false and *error names the key and its value.
  bool Validate(std::string* error) const { return ValidateByFirstProblem(*this, error); }
  std::string FirstProblem() const;  // "" if valid
};

// Seconds of data time between a frame and the start of the run.
inline double FrameTime(const FrameInputs& f) {
  return 1e-6 * static_cast<double>(f.utime - f.time_origin_utime);
}

}  // namespace vtrack::viewer
