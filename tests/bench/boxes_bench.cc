// The tracker core tracking from a detector's boxes only (--input-mode boxes): a whole KITTI
// tracking sequence of the boxes layout (PointRCNN car detections and the ORB-SLAM3 ego poses of
// ../shared/data/kitti_tracking_boxes, or $VTRACK_DATA_DIR/kitti_tracking_boxes), fed as
// vtrack-kitti2lcm writes it: ego poses every 10 ms and at each frame's time, then the frame's
// detection list. Everything is read and converted to the core's structs once, before timing;
// one iteration is the whole sequence through a fresh Tracker (Tracker::AddPose,
// AddDetections, Flush), one thread, measured in the thread's CPU time.
// Counter: frames_per_s (frames of the sequence per second of CPU time), one benchmark per mode
// (cv, ism, vasm, mht). Sequence: $VTRACK_BENCH_SEQUENCE, default 0020 (837 frames, 7,898
// detections: the largest of the set). Skipped, saying so, if the data is absent.
//
//   build/bench/boxes_bench [--benchmark_filter=mht]
#include <benchmark/benchmark.h>

#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <set>
#include <string>
#include <vector>

#include "sensor_driver/kitti/kitti_sequence.h"
#include "tracker/config.h"
#include "tracker/core/tracker.h"
#include "tracker/lcm_convert.h"

namespace {

namespace fs = std::filesystem;

struct Frame {
  std::vector<vtrack::EgoPose> poses;  // poses up to and including the frame's time
  vtrack::DetectionList boxes;
};

struct BoxesSequence {
  std::vector<Frame> frames;
  std::size_t detections = 0;
  std::string error;
};

std::string BoxesDir() {
  const char* d = std::getenv("VTRACK_DATA_DIR");
  return (d && *d ? std::string(d) : std::string(VTRACK_SOURCE_DIR "/../shared/data")) +
         "/kitti_tracking_boxes";
}

std::string SequenceName() {
  const char* s = std::getenv("VTRACK_BENCH_SEQUENCE");
  return s && *s ? std::string(s) : std::string("0020");
}

BoxesSequence Load() {
  BoxesSequence out;
  if (!fs::is_directory(BoxesDir())) {
    out.error = "KITTI boxes data not found (" + BoxesDir() + "; set VTRACK_DATA_DIR)";
    return out;
  }
  try {
    vtrack::kitti::SequenceOptions o;
    o.dir = BoxesDir();
    o.sequence = SequenceName();
    o.sink = [](const std::string&) {};
    const vtrack::kitti::Sequence seq(o);
    // As vtrack-kitti2lcm: poses every 10 ms over the frames' times, plus each frame's time.
    constexpr std::int64_t kPosePeriodUs = 10'000;
    std::set<std::int64_t> times;
    const std::int64_t t0 = seq.FrameUtime(0), t1 = seq.FrameUtime(seq.num_frames() - 1);
    for (std::int64_t t = t0; t <= t1; t += kPosePeriodUs) times.insert(t);
    for (int i = 0; i < seq.num_frames(); ++i) times.insert(seq.FrameUtime(i));
    auto it = times.begin();
    for (int i = 0; i < seq.num_frames(); ++i) {
      Frame f;
      const vtrack::detection_list_t msg = seq.Detections(i);
      for (; it != times.end() && *it <= msg.utime; ++it) {
        f.poses.push_back(vtrack::PoseFromLcm(seq.PoseAt(*it)));
      }
      f.boxes = vtrack::DetectionsFromLcm(msg);
      out.detections += f.boxes.boxes.size();
      out.frames.push_back(std::move(f));
    }
  } catch (const std::exception& e) {
    out.error = std::string("cannot read the boxes sequence: ") + e.what();
  }
  return out;
}

const BoxesSequence& Data() {
  static const BoxesSequence data = Load();
  return data;
}

vtrack::TrackerParams Params(vtrack::TrackerMode mode) {
  const std::string path = VTRACK_SOURCE_DIR "/config/tracker.yaml";
  vtrack::TrackerParams p =
      fs::exists(path) ? vtrack::LoadTrackerParams(path) : vtrack::TrackerParams{};
  p.manager.mode = mode;
  p.detections.mode = vtrack::InputMode::kBoxes;
  return p;
}

void BM_BoxesSequence(benchmark::State& state, vtrack::TrackerMode mode) {
  const BoxesSequence& data = Data();
  if (!data.error.empty()) {
    state.SkipWithError(data.error.c_str());
    return;
  }
  const vtrack::TrackerParams params = Params(mode);
  std::vector<vtrack::ScanOutput> out;
  std::size_t reports = 0;
  for (auto _ : state) {
    vtrack::Tracker tracker(params);
    reports = 0;
    for (const Frame& f : data.frames) {
      for (const vtrack::EgoPose& p : f.poses) tracker.AddPose(p, &out);
      vtrack::DetectionList boxes = f.boxes;
      tracker.AddDetections(std::move(boxes), &out);
      reports += out.size();
      out.clear();
    }
    tracker.Flush(&out);
    reports += out.size();
    out.clear();
  }
  const double frames = static_cast<double>(data.frames.size());
  state.counters["frames"] = frames;
  state.counters["detections"] = static_cast<double>(data.detections);
  state.counters["reports"] = static_cast<double>(reports);
  state.counters["frames_per_s"] =
      benchmark::Counter(frames * static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(data.frames.size()));
}

BENCHMARK_CAPTURE(BM_BoxesSequence, cv, vtrack::TrackerMode::kCv)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_BoxesSequence, ism, vtrack::TrackerMode::kIsm)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_BoxesSequence, vasm, vtrack::TrackerMode::kVasm)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_BoxesSequence, mht, vtrack::TrackerMode::kMht)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
