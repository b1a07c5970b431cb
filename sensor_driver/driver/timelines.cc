#include "sensor_driver/driver/timelines.h"

#include "lcmtypes/util/encode.h"

namespace vtrack::sim {

SimScanTimeline::SimScanTimeline(Simulator* sim, lcm::LCM* lcm, SweepOutput output,
                                 std::string truth_channel)
    : sim_(sim), lcm_(lcm), output_(std::move(output)),
      truth_channel_(std::move(truth_channel)) {}

void SimScanTimeline::Prepare(int i, std::int64_t lap_start_utime, std::int64_t lap) {
  sim_->MakeScan(i, lap_start_utime, lap * sim_->NumScans() + i, &scan_, &truth_);
}

void SimScanTimeline::Publish() {
  slices_ += SendSweep(output_, scan_, [&](const std::string& ch, const auto& msg) {
    if (lcm_util::Publish(lcm_, ch, msg, &buffer_) < 0) {
      log_.Warn("publish", "publishing " + ch + " failed (the bus refused it, or its arrays do not hold npoints)");
    }
  }, /*paced=*/true);
  points_ += scan_.npoints;
  if (!truth_channel_.empty() && lcm_->publish(truth_channel_, &truth_) < 0) {
    log_.Warn("publish_truth", "publishing " + truth_channel_ + " failed");
  }
}

SimPoseTimeline::SimPoseTimeline(Simulator* sim, lcm::LCM* lcm, std::string channel)
    : sim_(sim), lcm_(lcm), channel_(std::move(channel)) {}

void SimPoseTimeline::Prepare(int k, std::int64_t lap_start_utime, std::int64_t) {
  sim_->MakePose(k, lap_start_utime, &pose_);
}

void SimPoseTimeline::Publish() {
  if (lcm_->publish(channel_, &pose_) < 0) log_.Warn("publish", "publishing " + channel_ + " failed");
}

}  // namespace vtrack::sim
