// Decodes the messages of the renderer's channels (checked, lcmtypes/util/decode.h) and hands
// them to a FrameAssembler; slices of sweeps are joined into scans first
// (lcmtypes/util/ladar_slices.h; a partial sweep is drawn with the returns that arrived). Used by both the live bus path and the offline log path. A message
// that cannot be decoded is counted and reported at a limited rate, never thrown.
#pragma once

#include <cstddef>
#include <cstdint>
#include <map>
#include <string>

#include "lcmtypes/util/ladar_slices.h"
#include "lcmtypes/util/process.h"
#include "viewer/frame_assembler.h"
#include "viewer/validate.h"

namespace vtrack::viewer {

// Channel names (docs/design.md, section 1); each is a command-line option of vtrack-render.
struct Channels {
  std::string scan = "LADAR_SCAN";
  std::string slice = "LADAR_SLICE";  // sweeps sent as slices (ladar_slice_t), joined into scans
  std::string pose = "EGO_POSE";
  std::string tracks = "TRACKS";
  std::string debug = "TRACK_DEBUG";
  std::string truth = "GROUND_TRUTH";

  // True if every field is valid; otherwise false and *error names the key and its value.
  bool Validate(std::string* error) const { return ValidateByFirstProblem(*this, error); }
  std::string FirstProblem() const;  // "" if valid
};

class MessageRouter {
 public:
  MessageRouter(const Channels& channels, FrameAssembler* assembler);

  // Decodes a message and gives it to the assembler. Returns false if the channel is not one of
  // the renderer's (ignored) or the message could not be decoded (counted).
  bool Route(const std::string& channel, const void* data, std::size_t size);

  const std::map<std::string, std::int64_t>& received() const { return received_; }
  const std::map<std::string, std::int64_t>& decode_errors() const { return decode_errors_; }
  std::int64_t total_decode_errors() const;
  // Hands the sweeps still being assembled from slices to the assembler (end of the input).
  void Flush();
  const lcm_util::SweepAssembler& sweeps() const { return sweeps_; }

 private:
  template <class T>
  bool DecodeInto(const std::string& channel, const void* data, std::size_t size, T* out);

  Channels channels_;
  FrameAssembler* assembler_;
  lcm_util::SweepAssembler sweeps_;  // LADAR_SLICE -> whole or partial scans
  void AddSweeps(std::vector<lcm_util::AssembledSweep>* done);
  std::map<std::string, std::int64_t> received_;
  std::map<std::string, std::int64_t> decode_errors_;
  lcm_util::RateLimitedLog log_{"vtrack-render", 2.0};
};

}  // namespace vtrack::viewer
