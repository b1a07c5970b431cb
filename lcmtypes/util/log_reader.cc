#include "lcmtypes/util/log_reader.h"

#include <cstdio>
#include <filesystem>
#include <stdexcept>

namespace vtrack::lcm_util {

LogReader::LogReader(const std::string& path) : path_(path) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) {
    throw std::runtime_error("cannot open LCM log '" + path + "': no such file");
  }
  file_size_ = static_cast<std::int64_t>(std::filesystem::file_size(path, ec));
  log_ = std::make_unique<lcm::LogFile>(path, "r");
  if (!log_->good()) throw std::runtime_error("cannot open LCM log '" + path + "' for reading");
}

const lcm::LogEvent* LogReader::Next() { return log_->readNextEvent(); }

std::int64_t LogReader::BytesRead() const {
  FILE* f = log_->getFilePtr();
  return f ? static_cast<std::int64_t>(std::ftell(f)) : 0;
}

LogWriter::LogWriter(const std::string& path) : path_(path) {
  log_ = std::make_unique<lcm::LogFile>(path, "w");
  if (!log_->good()) throw std::runtime_error("cannot create LCM log '" + path + "'");
}

void LogWriter::Write(std::int64_t timestamp_us, const std::string& channel, const void* data,
                      std::size_t size) {
  lcm::LogEvent ev;
  ev.eventnum = next_event_++;
  ev.timestamp = timestamp_us;
  ev.channel = channel;
  ev.datalen = static_cast<int32_t>(size);
  ev.data = const_cast<void*>(data);
  if (log_->writeEvent(&ev) != 0) {
    throw std::runtime_error("write to LCM log '" + path_ + "' failed (disk full?)");
  }
}

}  // namespace vtrack::lcm_util
