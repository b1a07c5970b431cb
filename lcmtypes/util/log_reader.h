// Reading and writing LCM log files (the format of lcm-logger) with errors that say what failed.
#pragma once

#include <lcm/lcm-cpp.hpp>

#include <cstdint>
#include <memory>
#include <string>

namespace vtrack::lcm_util {

// Iterates the events of an LCM log file in file order.
class LogReader {
 public:
  // Throws std::runtime_error naming the path if the file cannot be opened.
  explicit LogReader(const std::string& path);
  // The next event, or nullptr at the end of the log. Valid until the next call.
  const lcm::LogEvent* Next();
  // Bytes read so far and the file size, for progress output.
  std::int64_t BytesRead() const;
  std::int64_t FileSize() const { return file_size_; }
  const std::string& path() const { return path_; }

 private:
  std::string path_;
  std::unique_ptr<lcm::LogFile> log_;
  std::int64_t file_size_ = 0;
};

// Appends events to a new LCM log file (event numbers are assigned in order).
class LogWriter {
 public:
  // Throws std::runtime_error naming the path if the file cannot be created.
  explicit LogWriter(const std::string& path);
  void Write(std::int64_t timestamp_us, const std::string& channel, const void* data,
             std::size_t size);
  template <class Msg>
  void WriteMessage(std::int64_t timestamp_us, const std::string& channel, const Msg& msg) {
    const int n = msg.getEncodedSize();
    buffer_.resize(static_cast<std::size_t>(n));
    msg.encode(buffer_.data(), 0, n);
    Write(timestamp_us, channel, buffer_.data(), buffer_.size());
  }
  std::int64_t events_written() const { return next_event_; }

 private:
  std::string path_;
  std::unique_ptr<lcm::LogFile> log_;
  std::int64_t next_event_ = 0;
  std::string buffer_;
};

}  // namespace vtrack::lcm_util
