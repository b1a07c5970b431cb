// The tracker's parameters in YAML (config/tracker.yaml): one section per component (input,
// preprocess, segmentation, association, fit, ism, vasm, ekf, shape, manager, detections), keys
// as each Params struct declares them in its Visit (tracker/core/params.h). Missing keys keep
// their defaults; an unknown or duplicate key, a value of the wrong type or out of its range, an
// empty file and a path that is not a file are errors naming the file, the key and the value.
#pragma once

#include <ostream>
#include <string>

#include "tracker/core/parameters.h"

namespace vtrack {

// Throws std::runtime_error naming the file, key and value on any problem.
TrackerParams LoadTrackerParams(const std::string& path);
// Same, from YAML text (origin names it in messages).
TrackerParams ParseTrackerParams(const std::string& yaml_text, const std::string& origin);

// params as a complete config file, every key with its unit and reason (the shipped
// config/tracker.yaml is this for the built-in defaults).
void WriteConfigYaml(const TrackerParams& params, std::ostream& out);
// The parameter reference in Markdown (docs/parameters.md): every key's default, unit, valid
// values and reason.
void WriteParameterReference(std::ostream& out);

}  // namespace vtrack
