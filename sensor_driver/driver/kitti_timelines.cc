#include "sensor_driver/driver/kitti_timelines.h"

#include <cmath>
#include <stdexcept>

#include "lcmtypes/util/encode.h"

namespace vtrack::sim {

namespace {
constexpr std::int64_t kFrameUs = 100000;  // KITTI tracking: 10 Hz frames
}  // namespace

kitti::SequenceOptions KittiCliOptions(const boost::program_options::variables_map& vm) {
  kitti::SequenceOptions o;
  o.dir = vm["kitti"].as<std::string>();
  o.sequence = vm["sequence"].as<std::string>();
  if (vm.count("poses")) o.poses_file = vm["poses"].as<std::string>();
  if (vm.count("oxts")) o.oxts_file = vm["oxts"].as<std::string>();
  if (vm.count("cache-dir")) o.cache_dir = vm["cache-dir"].as<std::string>();
  return o;
}

KittiTimeline::KittiTimeline(kitti::SequenceOptions options, lcm::LCM* lcm)
    : seq_(std::make_unique<kitti::Sequence>(std::move(options))),
      lcm_(lcm),
      base_(seq_->ScanUtime(0)) {}

std::int64_t KittiTimeline::LapUs() const { return seq_->num_frames() * kFrameUs; }

KittiScanTimeline::KittiScanTimeline(kitti::SequenceOptions options, lcm::LCM* lcm,
                                     SweepOutput output, std::string truth_channel,
                                     std::string detections_channel)
    : KittiTimeline(std::move(options), lcm),
      output_(std::move(output)),
      truth_channel_(std::move(truth_channel)),
      detections_channel_(std::move(detections_channel)) {
  // Refused before the first lap, not at its first scan: a folder of the boxes layout has no
  // point clouds to publish (vtrack-ego-pose takes it; its boxes come with vtrack-kitti2lcm).
  if (!seq().has_scans()) {
    throw kitti::KittiError(seq().options().dir + ": sequence " + seq().sequence() +
                            " has no Velodyne point clouds (the boxes layout): nothing to publish "
                            "as scans");
  }
}

std::int64_t KittiScanTimeline::PublishOffsetUs(int i) const {
  return seq().ScanUtime(i) - base() + seq().options().velodyne.sweep_duration_us;
}

void KittiScanTimeline::Prepare(int i, std::int64_t lap_start_utime, std::int64_t lap) {
  const std::int64_t shift = lap_start_utime - base();
  const kitti::VelodyneFrame frame = seq().ReadFrame(i);
  scan_ = seq().Scan(i, frame);
  scan_.utime += shift;
  scan_.seq = lap * seq().num_frames() + i;
  have_truth_ = !truth_channel_.empty() && seq().has_labels();
  if (have_truth_) {
    truth_ = seq().GroundTruth(i, frame);
    truth_.utime += shift;
    truth_.scan_seq = scan_.seq;
  }
  have_detections_ = !detections_channel_.empty() && seq().has_detections();
  if (have_detections_) {
    detections_ = seq().Detections(i);
    detections_.utime += shift;
    detections_.seq = scan_.seq;
  }
}

void KittiScanTimeline::Publish() {
  SendSweep(output_, scan_, [&](const std::string& ch, const auto& msg) {
    if (lcm_util::Publish(lcm(), ch, msg, &buffer_) < 0) {
      log_.Warn("publish", "publishing " + ch + " failed (the bus refused it, or its arrays do not hold npoints)");
    }
  }, /*paced=*/true);
  if (have_truth_ && lcm()->publish(truth_channel_, &truth_) < 0) {
    log_.Warn("publish_truth", "publishing " + truth_channel_ + " failed");
  }
  if (have_detections_ && lcm()->publish(detections_channel_, &detections_) < 0) {
    log_.Warn("publish_detections", "publishing " + detections_channel_ + " failed");
  }
}

KittiPoseTimeline::KittiPoseTimeline(kitti::SequenceOptions options, double rate_hz,
                                     lcm::LCM* lcm, std::string channel)
    : KittiTimeline(std::move(options), lcm), rate_hz_(rate_hz), channel_(std::move(channel)) {
  if (!(rate_hz_ >= 1.0 && rate_hz_ <= 1000.0)) {
    throw std::invalid_argument("--pose-rate = " + std::to_string(rate_hz_) + " Hz: must be in [1, 1000]");
  }
  while (PublishOffsetUs(count_) < LapUs()) ++count_;
}

std::int64_t KittiPoseTimeline::PublishOffsetUs(int k) const {
  return std::llround(k * 1e6 / rate_hz_);
}

void KittiPoseTimeline::Prepare(int k, std::int64_t lap_start_utime, std::int64_t) {
  pose_ = seq().PoseAt(base() + PublishOffsetUs(k));
  pose_.utime = lap_start_utime + PublishOffsetUs(k);
}

void KittiPoseTimeline::Publish() {
  if (lcm()->publish(channel_, &pose_) < 0) log_.Warn("publish", "publishing " + channel_ + " failed");
}

}  // namespace vtrack::sim
