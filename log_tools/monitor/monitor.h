// vtrack-monitor's model: per-channel statistics of an LCM bus or log (message count, rate,
// bandwidth, decode errors) and a one-line decoded summary of the latest vtrack message, rendered
// as a text table. lcm-spy does this in a GUI; vehicles are headless.
//
// Types are recognised by the 8-byte fingerprint that starts every LCM message. Every message is
// checked with lcm_util::CheckLengths (no allocation, so a malformed 2 MB scan costs nothing);
// only the latest message of a channel is fully decoded (lcm_util::Decode), when the table is
// rendered.
#pragma once

#include <cstddef>
#include <cstdint>
#include <deque>
#include <map>
#include <string>
#include <vector>

namespace vtrack::monitor {

// The vtrack type name for an LCM fingerprint ("track_list_t"), or "" if it is not a vtrack type.
std::string TypeName(std::int64_t fingerprint);

// One line describing an encoded message: its type and decoded content, or why it cannot be
// decoded. Never throws.
struct Description {
  std::string type;      // vtrack type name, or "? 0x<fingerprint>" for other types
  std::string summary;   // e.g. "seq 12 velodyne 120345 pts, sweep 100.0 ms, 64 rings"
  bool ok = false;       // decoded (or a foreign type, which is not an error)
};
Description Describe(const void* data, std::size_t size);

class ChannelTable {
 public:
  // window_s: live rates and bandwidth are averaged over the last window_s seconds.
  explicit ChannelTable(double window_s = 2.0);

  // Records a message received (live) or logged at time_us [us].
  void Add(const std::string& channel, std::int64_t time_us, const void* data, std::size_t size);

  struct Row {
    std::string channel;
    std::string type;
    std::int64_t count = 0;         // messages
    std::int64_t decode_errors = 0; // messages that failed the length/type check
    double rate_hz = 0.0;           // NaN if unknown (fewer than two messages)
    double bandwidth_bps = 0.0;     // [bytes/s]; NaN if unknown
    std::string summary;            // latest message
  };
  // whole_span = false (live): rates over the window ending at now_us.
  // whole_span = true (log): rates over each channel's span, (count - 1) / (last - first).
  std::vector<Row> Rows(std::int64_t now_us, bool whole_span) const;

  // A text table of Rows, lines cut to width characters (0 = no limit).
  std::string Render(std::int64_t now_us, bool whole_span, int width) const;

  std::int64_t total_messages() const { return total_messages_; }
  std::int64_t total_bytes() const { return total_bytes_; }

 private:
  struct Channel {
    std::int64_t count = 0, bytes = 0, decode_errors = 0;
    std::int64_t first_us = 0, last_us = 0;
    std::int64_t fingerprint = 0;
    std::deque<std::pair<std::int64_t, std::size_t>> recent;  // (time, size) within the window
    std::string last_message;
  };
  std::int64_t window_us_;
  std::map<std::string, Channel> channels_;
  std::int64_t total_messages_ = 0, total_bytes_ = 0;
};

}  // namespace vtrack::monitor
