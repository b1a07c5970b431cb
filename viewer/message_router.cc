#include "viewer/message_router.h"

#include <memory>
#include <set>

#include "lcmtypes/util/decode.h"

namespace vtrack::viewer {

std::string Channels::FirstProblem() const {
  const std::pair<const char*, const std::string*> all[] = {
      {"scan_channel", &scan}, {"slice_channel", &slice}, {"pose_channel", &pose}, {"tracks_channel", &tracks},
      {"debug_channel", &debug}, {"truth_channel", &truth}};
  std::set<std::string> seen;
  for (const auto& [key, value] : all) {
    if (value->empty()) return std::string("channels.") + key + " is empty";
    if (!seen.insert(*value).second) {
      return std::string("channels.") + key + " = '" + *value + "': used for two inputs";
    }
  }
  return {};
}

MessageRouter::MessageRouter(const Channels& channels, FrameAssembler* assembler)
    : channels_(channels), assembler_(assembler) {}

std::int64_t MessageRouter::total_decode_errors() const {
  std::int64_t n = 0;
  for (const auto& [channel, count] : decode_errors_) n += count;
  return n;
}

template <class T>
bool MessageRouter::DecodeInto(const std::string& channel, const void* data, std::size_t size,
                               T* out) {
  std::string why;
  const lcm_util::DecodeError err = lcm_util::Decode(data, size, out, &why);
  if (err == lcm_util::DecodeError::kNone) return true;
  ++decode_errors_[channel];
  log_.Warn("decode:" + channel, "cannot decode a message on " + channel + " (" +
                                     lcm_util::DecodeErrorName(err) +
                                     (why.empty() ? std::string() : ": " + why) + "); skipped");
  return false;
}

void MessageRouter::AddSweeps(std::vector<lcm_util::AssembledSweep>* done) {
  for (lcm_util::AssembledSweep& s : *done) {
    assembler_->AddScan(std::make_shared<vtrack::ladar_scan_t>(std::move(s.scan)));
  }
}

void MessageRouter::Flush() {
  std::vector<lcm_util::AssembledSweep> done;
  sweeps_.Flush(&done);
  AddSweeps(&done);
}

bool MessageRouter::Route(const std::string& channel, const void* data, std::size_t size) {
  try {
    if (channel == channels_.scan) {
      auto msg = std::make_shared<vtrack::ladar_scan_t>();
      if (!DecodeInto(channel, data, size, msg.get())) return false;
      ++received_[channel];
      assembler_->AddScan(std::move(msg));
    } else if (channel == channels_.slice) {
      vtrack::ladar_slice_t msg;
      if (!DecodeInto(channel, data, size, &msg)) return false;
      ++received_[channel];
      std::vector<lcm_util::AssembledSweep> done;
      sweeps_.Add(std::move(msg), &done);
      AddSweeps(&done);
    } else if (channel == channels_.pose) {
      vtrack::pose_t msg;
      if (!DecodeInto(channel, data, size, &msg)) return false;
      ++received_[channel];
      assembler_->AddPose(msg);
    } else if (channel == channels_.tracks) {
      auto msg = std::make_shared<vtrack::track_list_t>();
      if (!DecodeInto(channel, data, size, msg.get())) return false;
      ++received_[channel];
      assembler_->AddTracks(std::move(msg));
    } else if (channel == channels_.debug) {
      auto msg = std::make_shared<vtrack::track_debug_t>();
      if (!DecodeInto(channel, data, size, msg.get())) return false;
      ++received_[channel];
      assembler_->AddDebug(std::move(msg));
    } else if (channel == channels_.truth) {
      auto msg = std::make_shared<vtrack::object_list_t>();
      if (!DecodeInto(channel, data, size, msg.get())) return false;
      ++received_[channel];
      assembler_->AddTruth(std::move(msg));
    } else {
      return false;
    }
  } catch (const std::exception& e) {
    // Out of memory for a huge but well-formed message, and the like: skip it, keep running.
    ++decode_errors_[channel];
    log_.Warn("error:" + channel, "message on " + channel + " skipped: " + e.what());
    return false;
  }
  return true;
}

}  // namespace vtrack::viewer
