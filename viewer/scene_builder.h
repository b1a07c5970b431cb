// Turns one frame's messages (FrameInputs) into the renderer's Scene: LADAR points placed in the
// world exactly as the tracker places them (tracker/core/preprocess.h: every return with the ego
// pose interpolated at utime + dt_us[i], ground removed for 3-D clouds), tracks with their
// recent paths, the tracker's debug entries, ground truth with its path, and the ego vehicle.
#pragma once

#include <cstdint>
#include <string>

#include "tracker/core/preprocess.h"
#include "viewer/frame_assembler.h"
#include "viewer/scene.h"
#include "viewer/validate.h"

namespace vtrack::viewer {

struct SceneParams {
  PreprocessParams preprocess;                      // placement and filtering of the points
                                                    // (the tracker's defaults)
  std::int64_t max_pose_extrapolation_us = 200'000; // [us] past the newest pose
  double ego_length = 4.5;                          // [m] ego outline along its heading
  double ego_width = 1.8;                           // [m]
  double ego_center_ahead = 0.0;                    // [m] outline centre ahead of the body origin

  // True if every field is valid; otherwise false and *error names the key and its value.
  bool Validate(std::string* error) const { return ValidateByFirstProblem(*this, error); }
  std::string FirstProblem() const;  // "" if valid
};

class SceneBuilder {
 public:
  // Throws std::invalid_argument if the parameters are invalid.
  explicit SceneBuilder(const SceneParams& params);

  // Never throws on bad message content: what cannot be placed is left out and said in notes.
  Scene Build(const FrameInputs& in);

 private:
  SceneParams params_;
  Preprocessor preprocessor_;
  WorldPoints world_;
};

}  // namespace vtrack::viewer
