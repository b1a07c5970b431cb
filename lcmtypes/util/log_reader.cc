#include "lcmtypes/util/log_reader.h"

#include <cstdio>
#include <filesystem>
#include <stdexcept>

namespace vtrack::lcm_util {

namespace {

constexpr std::uint32_t kSyncWord = 0xEDA1DA01;
constexpr int kHeaderBytes = 4 + 8 + 8 + 4 + 4;
// Longest channel name accepted (LCM itself allows 63 on udpm; logs from other transports may
// hold longer ones). A header claiming more is damage.
constexpr std::int32_t kMaxChannelBytes = 4096;

std::uint64_t BigEndian(const unsigned char* p, int n) {
  std::uint64_t v = 0;
  for (int i = 0; i < n; ++i) v = (v << 8) | p[i];
  return v;
}

}  // namespace

LogReader::LogReader(const std::string& path) : path_(path) {
  std::error_code ec;
  const std::filesystem::file_status st = std::filesystem::status(path, ec);
  if (!std::filesystem::is_regular_file(st)) {
    throw std::runtime_error("cannot open LCM log '" + path + "': " +
                             (!std::filesystem::exists(st)       ? "no such file"
                              : std::filesystem::is_directory(st) ? "a directory, not a log file"
                                                                  : "not a regular file"));
  }
  file_size_ = static_cast<std::int64_t>(std::filesystem::file_size(path, ec));
  file_ = std::fopen(path.c_str(), "rb");
  if (file_ == nullptr) throw std::runtime_error("cannot open LCM log '" + path + "' for reading");
}

LogReader::~LogReader() {
  if (file_ != nullptr) std::fclose(file_);
}

bool LogReader::Seek(std::int64_t offset) {
  return std::fseek(file_, static_cast<long>(offset), SEEK_SET) == 0;
}

bool LogReader::ReadHeader(std::int64_t* eventnum, std::int64_t* timestamp,
                           std::int32_t* channel_len, std::int32_t* data_len) {
  unsigned char h[kHeaderBytes];
  if (offset_ + kHeaderBytes > file_size_ || (std::ftell(file_) != offset_ && !Seek(offset_)) ||
      std::fread(h, 1, kHeaderBytes, file_) != kHeaderBytes) {
    return false;
  }
  if (BigEndian(h, 4) != kSyncWord) return false;
  *eventnum = static_cast<std::int64_t>(BigEndian(h + 4, 8));
  *timestamp = static_cast<std::int64_t>(BigEndian(h + 12, 8));
  const auto clen = static_cast<std::int32_t>(BigEndian(h + 20, 4));
  const auto dlen = static_cast<std::int32_t>(BigEndian(h + 24, 4));
  if (clen <= 0 || clen > kMaxChannelBytes || dlen < 0) return false;
  if (offset_ + kHeaderBytes + clen + dlen > file_size_) return false;  // cut short
  *channel_len = clen;
  *data_len = dlen;
  return true;
}

void LogReader::Resync() {
  const std::int64_t start = offset_;
  std::int64_t eventnum, timestamp;
  std::int32_t clen, dlen;
  // Search byte by byte for the sync word, then check the header that follows it.
  std::uint32_t window = 0;
  std::int64_t pos = start + 1;
  Seek(pos);
  int c;
  while ((c = std::fgetc(file_)) != EOF) {
    window = (window << 8) | static_cast<std::uint32_t>(c);
    ++pos;
    if (window != kSyncWord || pos - 4 <= start) continue;
    offset_ = pos - 4;
    if (ReadHeader(&eventnum, &timestamp, &clen, &dlen)) break;
    Seek(pos);  // not an event: go on after the sync word's first byte
    window = kSyncWord & 0x00FFFFFF;
  }
  if (c == EOF) offset_ = file_size_;
  ++damage_.regions;
  damage_.bytes_skipped += offset_ - start;
  if (damage_.first_offset < 0) damage_.first_offset = start;
  damage_.truncated = offset_ >= file_size_;
}

const lcm::LogEvent* LogReader::Next() {
  std::int64_t eventnum, timestamp;
  std::int32_t clen, dlen;
  while (offset_ < file_size_) {
    if (!ReadHeader(&eventnum, &timestamp, &clen, &dlen)) {
      Resync();
      continue;
    }
    channel_.resize(static_cast<std::size_t>(clen));
    // The buffer only grows: a vector grown again after a pose's few bytes zeroes the whole of
    // the next sweep's 2.7 MB before it is read over (2.5 % of a KITTI replay's instructions).
    const auto size = static_cast<std::size_t>(dlen);
    if (data_.size() < size) data_.resize(size);
    if (std::fread(channel_.data(), 1, channel_.size(), file_) != channel_.size() ||
        std::fread(data_.data(), 1, size, file_) != size) {
      Resync();  // the file shrank while it was read
      continue;
    }
    offset_ += kHeaderBytes + clen + dlen;
    ++events_read_;
    event_.eventnum = eventnum;
    event_.timestamp = timestamp;
    event_.channel = channel_;
    event_.datalen = dlen;
    event_.data = data_.data();
    return &event_;
  }
  return nullptr;
}

std::string LogReader::DamageSummary() const {
  if (!damaged()) return "";
  if (events_read_ == 0 && damage_.first_offset == 0 && damage_.bytes_skipped == file_size_) {
    // Nothing in it is an event: no log at all, rather than a log cut short.
    return "log '" + path_ + "' holds no LCM event: none of its " + std::to_string(file_size_) +
           " bytes starts a whole one (not an LCM log, or one cut short within its first event)";
  }
  return "log '" + path_ + "' is damaged: " + std::to_string(damage_.bytes_skipped) +
         " bytes in " + std::to_string(damage_.regions) + " place(s) skipped, the first at byte " +
         std::to_string(damage_.first_offset) + (damage_.truncated ? " (cut short at the end)" : "") +
         "; " + std::to_string(events_read_) + " whole events read";
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
  bytes_written_ += 28 + static_cast<std::int64_t>(channel.size() + size);
}

}  // namespace vtrack::lcm_util
