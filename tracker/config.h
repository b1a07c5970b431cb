// Loading the tracker's parameters from YAML (config/tracker.yaml). One section per component
// (input, preprocess, segmentation, association, fit, ism, vasm, ekf, shape, manager); keys are
// the field names of the core Params structs. Missing keys keep their defaults; an unknown key,
// a value of the wrong type or an invalid value is an error that names the file, the key and
// the value.
#pragma once

#include <string>

#include "tracker/core/tracker_params.h"

namespace vtrack {

// Throws std::runtime_error naming the file, key and value on any problem.
TrackerParams LoadTrackerParams(const std::string& path);
// Same, from YAML text (origin names it in messages).
TrackerParams ParseTrackerParams(const std::string& yaml_text, const std::string& origin);

}  // namespace vtrack
