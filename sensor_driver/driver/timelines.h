// What the two live processes publish, as Timelines (realtime.h): a scenario's scans + ground
// truth and its ego poses, or (kitti_timelines.h) a KITTI sequence's.
#pragma once

#include <lcm/lcm-cpp.hpp>

#include <cstdint>
#include <string>
#include <vector>

#include "lcmtypes/util/process.h"
#include "sensor_driver/driver/realtime.h"
#include "sensor_driver/sim/simulator.h"
#include "sensor_driver/sim/sweep_output.h"

namespace vtrack::sim {

// LADAR_SCAN or LADAR_SLICE (output) + GROUND_TRUTH of a scenario. seq = lap * NumScans() + i.
class SimScanTimeline : public Timeline {
 public:
  SimScanTimeline(Simulator* sim, lcm::LCM* lcm, SweepOutput output,
                  std::string truth_channel /* "" = do not publish ground truth */);
  int Count() const override { return sim_->NumScans(); }
  std::int64_t LapUs() const override { return sim_->RunDurationUs(); }
  std::int64_t PublishOffsetUs(int i) const override { return sim_->ScanPublishOffsetUs(i); }
  void Prepare(int i, std::int64_t lap_start_utime, std::int64_t lap) override;
  void Publish() override;
  std::int64_t points_published() const { return points_; }
  std::int64_t slices_published() const { return slices_; }

 private:
  Simulator* sim_;
  lcm::LCM* lcm_;
  SweepOutput output_;
  std::vector<std::uint8_t> buffer_;  // a sweep's encoding, kept from sweep to sweep
  std::string truth_channel_;
  vtrack::ladar_scan_t scan_;
  vtrack::object_list_t truth_;
  std::int64_t points_ = 0, slices_ = 0;
  lcm_util::RateLimitedLog log_{"vtrack-ladar-driver"};
};

// EGO_POSE of a scenario.
class SimPoseTimeline : public Timeline {
 public:
  SimPoseTimeline(Simulator* sim, lcm::LCM* lcm, std::string channel);
  int Count() const override { return sim_->NumPoses(); }
  std::int64_t LapUs() const override { return sim_->RunDurationUs(); }
  std::int64_t PublishOffsetUs(int k) const override { return sim_->PoseOffsetUs(k); }
  void Prepare(int k, std::int64_t lap_start_utime, std::int64_t lap) override;
  void Publish() override;

 private:
  Simulator* sim_;
  lcm::LCM* lcm_;
  std::string channel_;
  vtrack::pose_t pose_;
  lcm_util::RateLimitedLog log_{"vtrack-ego-pose"};
};

}  // namespace vtrack::sim
