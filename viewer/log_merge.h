// Reads several LCM log files as one stream, merged by event time (e.g. a simulator log and the
// tracker's output log of the same run).
#pragma once

#include <lcm/lcm-cpp.hpp>

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "lcmtypes/util/log_reader.h"

namespace vtrack::viewer {

class MergedLogReader {
 public:
  // Throws std::runtime_error naming the path if a log cannot be opened.
  explicit MergedLogReader(const std::vector<std::string>& paths);

  // The event with the smallest event timestamp among the logs' next events (ties: the log given
  // first), or nullptr when every log is exhausted. Valid until the next call. *source, if
  // given, is the index of the log it came from.
  const lcm::LogEvent* Next(std::size_t* source = nullptr);

  // Bytes read so far over all logs, and their total size (for progress).
  std::int64_t BytesRead() const;
  std::int64_t TotalBytes() const;
  // What was skipped of each damaged log (garbage, impossible lengths, a cut end), as messages.
  std::vector<std::string> IncompleteLogs() const;

 private:
  std::vector<std::unique_ptr<lcm_util::LogReader>> readers_;
  std::vector<const lcm::LogEvent*> heads_;
  std::ptrdiff_t consumed_ = -1;  // log whose head was handed out last
};

}  // namespace vtrack::viewer
