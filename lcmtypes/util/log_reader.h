// Reading and writing LCM log files (the format of lcm-logger) with errors that say what failed.
#pragma once

#include <lcm/lcm-cpp.hpp>

#include <cstdint>
#include <cstdio>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "lcmtypes/util/encode.h"

namespace vtrack::lcm_util {

// Where a log was damaged: bytes that are not a whole event (garbage between events, a header
// with an impossible length, an event cut short at the end of the file).
struct LogDamage {
  std::int64_t regions = 0;        // runs of bytes skipped
  std::int64_t bytes_skipped = 0;  // [bytes] in all
  std::int64_t first_offset = -1;  // [bytes] where the first run starts (-1: none)
  bool truncated = false;          // the last run reaches the end of the file
};

// Iterates the events of an LCM log file (the lcm-logger format: per event a big-endian header
// of sync word 0xEDA1DA01, event number, timestamp, channel length and data length, then the
// channel and the data) in file order. Read here rather than with lcm::LogFile: liblcm 1.3.1
// writes through a NULL buffer on a data length near 2^31 and ends silently at garbage or a cut
// event. Damage is skipped to the next whole event and counted (damage(), DamageSummary()).
class LogReader {
 public:
  // Throws std::runtime_error naming the path if the file cannot be opened.
  explicit LogReader(const std::string& path);
  ~LogReader();
  LogReader(const LogReader&) = delete;
  LogReader& operator=(const LogReader&) = delete;

  // The next whole event, or nullptr at the end of the log. Valid until the next call.
  const lcm::LogEvent* Next();
  // Bytes read so far and the file size, for progress output.
  std::int64_t BytesRead() const { return offset_; }
  std::int64_t FileSize() const { return file_size_; }
  const std::string& path() const { return path_; }
  std::int64_t events_read() const { return events_read_; }
  const LogDamage& damage() const { return damage_; }
  bool damaged() const { return damage_.regions > 0; }
  // "log 'P' is damaged: N bytes in R places skipped, the first at byte B (cut short at the
  // end); E whole events read", "log 'P' holds no LCM event: ..." if no byte of it was read
  // as an event, or "" if it is not damaged.
  std::string DamageSummary() const;

 private:
  // Reads the header at offset_; true and the lengths if it is a plausible event header that
  // fits in the file.
  bool ReadHeader(std::int64_t* eventnum, std::int64_t* timestamp, std::int32_t* channel_len,
                  std::int32_t* data_len);
  // Skips from offset_ to the next plausible event header (or the end), counting the damage.
  void Resync();
  bool Seek(std::int64_t offset);

  std::string path_;
  std::FILE* file_ = nullptr;
  std::int64_t file_size_ = 0;
  std::int64_t offset_ = 0;
  std::int64_t events_read_ = 0;
  LogDamage damage_;
  std::string channel_;
  std::vector<unsigned char> data_;  // the event's bytes first; as large as the largest event read
  lcm::LogEvent event_;
};

// Appends events to a new LCM log file (event numbers are assigned in order).
class LogWriter {
 public:
  // Throws std::runtime_error naming the path if the file cannot be created.
  explicit LogWriter(const std::string& path);
  void Write(std::int64_t timestamp_us, const std::string& channel, const void* data,
             std::size_t size);
  // Throws std::invalid_argument if msg cannot be encoded (encode.h: a point cloud whose arrays
  // do not hold npoints elements; a message whose generated encoder writes fewer bytes than it
  // announces, as with a string holding a NUL).
  template <class Msg>
  void WriteMessage(std::int64_t timestamp_us, const std::string& channel, const Msg& msg) {
    const int n = Encode(msg, &buffer_);
    if (n < 0) {
      throw std::invalid_argument(std::string("cannot encode a ") + Msg::getTypeName() + " for " +
                                  channel + " in " + path_);
    }
    Write(timestamp_us, channel, buffer_.data(), static_cast<std::size_t>(n));
  }
  std::int64_t events_written() const { return next_event_; }
  // Bytes of the events written so far, as the file holds them once flushed: per event the LCM
  // log header (sync word, event number, timestamp, channel and data lengths: 28 bytes), the
  // channel name and the data.
  std::int64_t bytes_written() const { return bytes_written_; }

 private:
  std::string path_;
  std::unique_ptr<lcm::LogFile> log_;
  std::int64_t next_event_ = 0;
  std::int64_t bytes_written_ = 0;
  std::vector<std::uint8_t> buffer_;
};

}  // namespace vtrack::lcm_util
