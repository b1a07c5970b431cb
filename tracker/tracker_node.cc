#include "tracker/tracker_node.h"

#include <algorithm>
#include <cmath>
#include <exception>
#include <stdexcept>

#include "lcmtypes/util/decode.h"
#include "lcmtypes/util/encode.h"
#include "tracker/lcm_convert.h"
#include "vtrack/ladar_scan_t.hpp"
#include "vtrack/ladar_slice_t.hpp"
#include "vtrack/pose_t.hpp"

namespace vtrack {

TrackerNode::TrackerNode(const TrackerParams& params, NodeOptions options, PublishFn publish)
    : params_(params),
      options_(std::move(options)),
      publish_(std::move(publish)),
      tracker_(params, options_.debug) {
  tracker_.SetFirstTrackId(options_.first_track_id);
  tracker_.SetSeed(options_.seed);
  if (!options_.evidence_csv.empty()) {
    evidence_csv_.open(options_.evidence_csv);
    if (!evidence_csv_) {
      throw std::invalid_argument("cannot write the evidence CSV '" + options_.evidence_csv + "'");
    }
    evidence_csv_.precision(7);
    evidence_csv_ << "utime,track_id,x,y,three_d";
    for (std::size_t k = 0; k < kNumEvidenceFeatures; ++k) {
      evidence_csv_ << ',' << NameOf(static_cast<EvidenceFeature>(k));
    }
    evidence_csv_ << ",logit,log_odds\n";
    tracker_.SetRecordEvidence(true);
  }
}

void TrackerNode::WriteEvidence(const ScanOutput& o) {
  for (const ScanOutput::EvidenceRow& r : o.evidence) {
    // The track's reported centre (it is reported: every track is, after its update).
    const auto t = std::find_if(o.tracks.begin(), o.tracks.end(),
                                [&](const TrackReport& tr) { return tr.id == r.track_id; });
    evidence_csv_ << o.utime << ',' << r.track_id << ',';
    if (t != o.tracks.end()) evidence_csv_ << t->x << ',' << t->y;
    else evidence_csv_ << "nan,nan";  // deleted by the same scan's life cycle
    evidence_csv_ << ',' << (r.three_d ? 1 : 0);
    for (const double f : r.features) evidence_csv_ << ',' << f;
    evidence_csv_ << ',' << r.logit << ',' << r.log_odds << '\n';
  }
  if (!evidence_csv_) throw std::runtime_error("writing the evidence CSV '" + options_.evidence_csv + "' failed");
}

template <class Msg>
bool TrackerNode::DecodeOrCount(const std::string& channel, const void* data, std::size_t size,
                                Msg* msg) {
  std::string why;
  const auto err = lcm_util::Decode(data, size, msg, &why);
  if (err == lcm_util::DecodeError::kNone) return true;
  ++decode_errors_;
  ++decode_reasons_[lcm_util::DecodeErrorName(err)];
  log_.Warn(lcm_util::DecodeErrorName(err), "dropped a " + channel + " message of " +
                                                std::to_string(size) + " bytes: " +
                                                lcm_util::DecodeErrorName(err) +
                                                (why.empty() ? "" : " (" + why + ")"));
  return false;
}

void TrackerNode::NoteArrival(std::int64_t utime) {
  arrival_.emplace_back(utime, lcm_util::WallUtime());
  if (arrival_.size() > 1000) arrival_.pop_front();
}

void TrackerNode::Handle(const std::string& channel, const void* data, std::size_t size) {
  // An LCM callback must never let an exception escape: anything unexpected is counted.
  try {
    if (channel == options_.scan_channel) {
      ladar_scan_t msg;
      LendArrays(tracker_.TakeSpareScan(), &msg);
      if (!DecodeOrCount(channel, data, size, &msg)) return;
      returns_received_ += msg.npoints;
      NoteArrival(msg.utime);
      tracker_.AddScan(ScanFromLcm(std::move(msg)), &outs_);
    } else if (channel == options_.slice_channel) {
      ladar_slice_t msg;
      if (!DecodeOrCount(channel, data, size, &msg)) return;
      returns_received_ += msg.npoints;
      assembler_.Add(std::move(msg), &sweeps_);
      FeedSweeps();
    } else if (channel == options_.pose_channel) {
      pose_t msg;
      if (!DecodeOrCount(channel, data, size, &msg)) return;
      assembler_.Expire(msg.utime, &sweeps_);
      FeedSweeps();
      tracker_.AddPose(PoseFromLcm(msg), &outs_);
    } else if (channel == options_.detections_channel &&
               params_.detections.mode != InputMode::kScans) {
      detection_list_t msg;
      if (!DecodeOrCount(channel, data, size, &msg)) return;
      NoteArrival(msg.utime);
      tracker_.AddDetections(DetectionsFromLcm(msg), &outs_);
    } else {
      return;
    }
  } catch (const std::exception& e) {
    ++decode_reasons_["internal_error"];
    log_.Warn("internal_error", std::string("message on ") + channel + " dropped: " + e.what());
    outs_.clear();
  }
  Emit(&outs_);
  Warn();
}

void TrackerNode::FeedSweeps() {
  for (lcm_util::AssembledSweep& s : sweeps_) {
    NoteArrival(s.scan.utime);
    tracker_.AddScan(ScanFromLcm(std::move(s)), &outs_);
  }
  sweeps_.clear();
}

void TrackerNode::Flush() {
  try {
    assembler_.Flush(&sweeps_);
    FeedSweeps();
    tracker_.Flush(&outs_);
  } catch (const std::exception& e) {
    ++decode_reasons_["internal_error"];
    log_.Warn("internal_error", std::string("flush failed: ") + e.what());
    outs_.clear();
  }
  Emit(&outs_);
  Warn();
}

void TrackerNode::Warn() {
  for (const auto& e : tracker_.TakeEvents()) {
    if (e.reason == "reset") {
      std::fprintf(stderr, "vtrack-tracker: %s\n", e.message.c_str());  // always said
    } else {
      log_.Warn(e.reason, e.message);
    }
  }
}

void TrackerNode::Emit(std::vector<ScanOutput>* outs) {
  const std::string mode = ToString(params_.manager.mode);
  for (const ScanOutput& o : *outs) {
    std::int64_t latency_us = 0;
    const auto it = std::find_if(arrival_.begin(), arrival_.end(),
                                 [&](const auto& a) { return a.first == o.utime; });
    if (it != arrival_.end()) {
      latency_us = lcm_util::WallUtime() - it->second;
      arrival_.erase(arrival_.begin(), it + 1);
    }
    last_latency_ms_ = latency_us * 1e-3;
    latencies_ms_.push_back(last_latency_ms_);
    if (latencies_ms_.size() > 100) latencies_ms_.pop_front();
    const track_list_t msg = TrackListToLcm(o, mode, latency_us);
    lcm_util::Encode(msg, &buffer_);
    publish_(o.utime, options_.tracks_channel, buffer_.data(), buffer_.size());
    ++tracks_published_;
    if (evidence_csv_.is_open()) WriteEvidence(o);
    if (options_.debug) {
      const track_debug_t dbg = DebugToLcm(o);
      lcm_util::Encode(dbg, &buffer_);
      publish_(o.utime, options_.debug_channel, buffer_.data(), buffer_.size());
    }
    last_tentative_ = last_confirmed_ = last_coasting_ = 0;
    for (const auto& t : o.tracks) {
      if (t.status == TrackStatus::kTentative) ++last_tentative_;
      else if (t.status == TrackStatus::kConfirmed) ++last_confirmed_;
      else ++last_coasting_;
    }
  }
  outs->clear();
}

tracker_status_t TrackerNode::Status() const {
  tracker_status_t s;
  s.utime = tracker_.latest_utime();
  s.wall_utime = lcm_util::WallUtime();
  s.mode = ToString(params_.manager.mode);
  s.scans_received = tracker_.scans_received() ;
  s.scans_processed = tracker_.scans_processed();
  s.scans_dropped = tracker_.scans_dropped();
  s.poses_received = tracker_.poses_received();
  s.decode_errors = decode_errors_;
  s.resets = tracker_.resets();
  std::map<std::string, std::int64_t> reasons = tracker_.rejects();
  for (const auto& [k, v] : decode_reasons_) reasons[k] += v;
  for (const auto& [k, v] : assembler_.refused()) reasons[k] += v;
  if (assembler_.slices_lost() > 0) {
    reasons["slice_lost"] = assembler_.slices_lost();
    reasons["slice_lost_deg"] = std::llround(assembler_.missing_deg());
  }
  s.num_reasons = static_cast<int32_t>(reasons.size());
  for (const auto& [k, v] : reasons) {
    s.reject_reason.push_back(k);
    s.reject_count.push_back(v);
  }
  s.last_latency_ms = last_latency_ms_;
  std::vector<double> l(latencies_ms_.begin(), latencies_ms_.end());
  if (!l.empty()) {
    std::nth_element(l.begin(), l.begin() + static_cast<std::ptrdiff_t>(l.size() / 2), l.end());
    s.median_latency_ms = l[l.size() / 2];
  } else {
    s.median_latency_ms = 0.0;
  }
  s.tracks_tentative = static_cast<int32_t>(last_tentative_);
  s.tracks_confirmed = static_cast<int32_t>(last_confirmed_);
  s.tracks_coasting = static_cast<int32_t>(last_coasting_);
  return s;
}

void TrackerNode::PublishStatus(std::int64_t event_utime) {
  const tracker_status_t s = Status();
  lcm_util::Encode(s, &buffer_);
  publish_(event_utime, options_.status_channel, buffer_.data(), buffer_.size());
}

}  // namespace vtrack
