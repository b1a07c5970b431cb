// The --kitti source of vtrack-ladar-driver and vtrack-ego-pose: a KITTI tracking sequence
// (sensor_driver/kitti, vtrack::kitti::Sequence) laid out as a lap on the same wall-clock
// schedule as a scenario (realtime.h). Lap time 0 is the sequence's first sweep start
// (Sequence::ScanUtime(0)); a lap lasts num_frames * 100 ms; every utime of the sequence is moved
// by the lap's start, so consecutive laps replay the sequence with time running on. Poses are
// interpolated by Sequence::PoseAt at the requested rate over [0, lap); the last sweep's final
// 100 ms / rate is left to the consumer's extrapolation.
#pragma once

#include <boost/program_options.hpp>
#include <lcm/lcm-cpp.hpp>

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "lcmtypes/util/process.h"
#include "sensor_driver/driver/realtime.h"
#include "sensor_driver/sim/sweep_output.h"
#include "sensor_driver/kitti/kitti_sequence.h"

namespace vtrack::sim {

// --kitti, --sequence, --poses, --oxts, --cache-dir as SequenceOptions.
kitti::SequenceOptions KittiCliOptions(const boost::program_options::variables_map& vm);

// What both KITTI timelines hold: the sequence, the bus, and lap time 0.
class KittiTimeline : public Timeline {
 public:
  std::int64_t LapUs() const override;  // num_frames * 100 ms
  // The sequence read (NNNN; the folder's only one when none was named).
  const std::string& Sequence() const { return seq().sequence(); }

 protected:
  // Throws kitti::KittiError for a missing or malformed sequence.
  KittiTimeline(kitti::SequenceOptions options, lcm::LCM* lcm);
  const kitti::Sequence& seq() const { return *seq_; }
  lcm::LCM* lcm() const { return lcm_; }
  std::int64_t base() const { return base_; }

 private:
  std::unique_ptr<kitti::Sequence> seq_;
  lcm::LCM* lcm_;
  std::int64_t base_;  // ScanUtime(0): lap time 0
};

class KittiScanTimeline : public KittiTimeline {
 public:
  // Throws kitti::KittiError for a missing or malformed sequence.
  // detections_channel: the detector's boxes of the frame (detections/pointrcnn_Car), published
  // right after its sweep as vtrack-kitti2lcm writes them; "" or a sequence without them = none.
  KittiScanTimeline(kitti::SequenceOptions options, lcm::LCM* lcm, SweepOutput output,
                    std::string truth_channel /* "" = no ground truth */,
                    std::string detections_channel = "");
  int Count() const override { return seq().num_frames(); }
  std::int64_t PublishOffsetUs(int i) const override;
  void Prepare(int i, std::int64_t lap_start_utime, std::int64_t lap) override;
  void Publish() override;

 private:
  SweepOutput output_;
  std::vector<std::uint8_t> buffer_;  // a sweep's encoding, kept from sweep to sweep
  std::string truth_channel_;
  std::string detections_channel_;
  vtrack::ladar_scan_t scan_;
  vtrack::object_list_t truth_;
  vtrack::detection_list_t detections_;
  bool have_truth_ = false;
  bool have_detections_ = false;
  lcm_util::RateLimitedLog log_{"vtrack-ladar-driver"};
};

class KittiPoseTimeline : public KittiTimeline {
 public:
  KittiPoseTimeline(kitti::SequenceOptions options, double rate_hz, lcm::LCM* lcm,
                    std::string channel);
  int Count() const override { return count_; }
  std::int64_t PublishOffsetUs(int k) const override;
  void Prepare(int k, std::int64_t lap_start_utime, std::int64_t lap) override;
  void Publish() override;

 private:
  double rate_hz_;
  std::string channel_;
  int count_ = 0;
  vtrack::pose_t pose_;
  lcm_util::RateLimitedLog log_{"vtrack-ego-pose"};
};

}  // namespace vtrack::sim
