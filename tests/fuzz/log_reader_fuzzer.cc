// libFuzzer harness for lcm_util::LogReader: the input is a whole LCM log file (events of the
// lcm-logger format, garbage, impossible lengths, cut events), read from an in-memory file.
//
// Oracle, computed from the input bytes independently of the reader:
//  - every event the reader returns is a whole event of the file: at some offset at or after the
//    end of the previous one lies a header with its sync word, event number, timestamp and
//    lengths, followed by its channel and data bytes, and it ends within the file;
//  - nothing whole is skipped: no offset between two events read (or after the last one) starts
//    a plausible event header whose event fits in the file;
//  - events read + bytes skipped account for the whole file, and the reader ends at its end.
#include <sys/mman.h>
#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>

#include "lcmtypes/util/log_reader.h"

namespace {

constexpr std::size_t kHeaderBytes = 4 + 8 + 8 + 4 + 4;
// The reader's longest channel name (log_reader.cc): a header claiming more is damage.
constexpr std::int64_t kMaxChannelBytes = 4096;

std::uint64_t BigEndian(const std::uint8_t* p, int n) {
  std::uint64_t v = 0;
  for (int i = 0; i < n; ++i) v = (v << 8) | p[i];
  return v;
}

// True if a plausible event header starts at offset at and its event fits in the file.
bool WholeEventAt(const std::uint8_t* d, std::size_t size, std::size_t at) {
  if (at + kHeaderBytes > size || BigEndian(d + at, 4) != 0xEDA1DA01u) return false;
  const auto clen = static_cast<std::int32_t>(BigEndian(d + at + 20, 4));
  const auto dlen = static_cast<std::int32_t>(BigEndian(d + at + 24, 4));
  if (clen <= 0 || clen > kMaxChannelBytes || dlen < 0) return false;
  return static_cast<std::int64_t>(at + kHeaderBytes) + clen + dlen <= static_cast<std::int64_t>(size);
}

// True if ev is the whole event at offset at.
bool IsEventAt(const std::uint8_t* d, std::size_t size, std::size_t at, const lcm::LogEvent& ev) {
  if (!WholeEventAt(d, size, at)) return false;
  const std::size_t clen = ev.channel.size();
  const std::size_t dlen = static_cast<std::size_t>(ev.datalen);
  return static_cast<std::int64_t>(BigEndian(d + at + 4, 8)) == ev.eventnum &&
         static_cast<std::int64_t>(BigEndian(d + at + 12, 8)) == ev.timestamp &&
         BigEndian(d + at + 20, 4) == clen && BigEndian(d + at + 24, 4) == dlen &&
         std::memcmp(d + at + kHeaderBytes, ev.channel.data(), clen) == 0 &&
         (dlen == 0 || std::memcmp(d + at + kHeaderBytes + clen, ev.data, dlen) == 0);
}

[[noreturn]] void Fail(const char* what, std::size_t at) {
  std::fprintf(stderr, "log_reader_fuzzer: %s (byte %zu)\n", what, at);
  std::abort();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  // The reader takes a path: the input goes to an anonymous in-memory file.
  const int fd = memfd_create("vtrack_log_fuzz", 0);
  if (fd < 0) return 0;
  std::size_t written = 0;
  while (written < size) {
    const ssize_t n = write(fd, data + written, size - written);
    if (n <= 0) {
      close(fd);
      return 0;
    }
    written += static_cast<std::size_t>(n);
  }
  {
    vtrack::lcm_util::LogReader reader("/proc/self/fd/" + std::to_string(fd));
    std::size_t end = 0;  // end of the previous event
    std::int64_t event_bytes = 0, events = 0;
    while (const lcm::LogEvent* ev = reader.Next()) {
      if (ev->datalen < 0 || ev->channel.empty()) Fail("event with a negative length", end);
      std::size_t at = end;
      while (at < size && !IsEventAt(data, size, at, *ev)) {
        if (WholeEventAt(data, size, at)) Fail("a whole event was skipped", at);
        ++at;
      }
      if (at >= size) Fail("an event that is not in the file", end);
      end = at + kHeaderBytes + ev->channel.size() + static_cast<std::size_t>(ev->datalen);
      event_bytes += static_cast<std::int64_t>(end - at);
      ++events;
    }
    for (std::size_t at = end; at < size; ++at) {
      if (WholeEventAt(data, size, at)) Fail("a whole event after the last one read", at);
    }
    if (events != reader.events_read()) Fail("events_read() differs from the events returned", end);
    if (event_bytes + reader.damage().bytes_skipped != static_cast<std::int64_t>(size)) {
      Fail("events read + bytes skipped do not account for the file", end);
    }
    if (reader.BytesRead() != reader.FileSize() || reader.FileSize() != static_cast<std::int64_t>(size)) {
      Fail("the reader did not end at the end of the file", end);
    }
    if (reader.damaged() != (reader.damage().bytes_skipped > 0)) Fail("damage said wrongly", end);
  }
  close(fd);
  return 0;
}
