// vtrack-kitti2lcm: the conversion (library) on a synthetic sequence, the process's options and
// errors, and the real sequence 0000 (skipped when ../shared/data is absent).
#include <gtest/gtest.h>

#include <csignal>
#include <filesystem>
#include <thread>
#include <fstream>
#include <map>
#include <set>

#include "lcmtypes/util/decode.h"
#include "lcmtypes/util/log_reader.h"
#include "log_tools/kitti2lcm/converter.h"
#include "sensor_driver/kitti/kitti_sequence.h"
#include "tests/sensor_driver/kitti_synthetic.h"
#include "tests/support/subprocess.h"
#include "tests/support/test_env.h"
#include "vtrack/detection_list_t.hpp"
#include "vtrack/ladar_scan_t.hpp"
#include "vtrack/object_list_t.hpp"
#include "vtrack/pose_t.hpp"

namespace vtrack::kitti {
namespace {

namespace fs = std::filesystem;
using vtrack::lcm_util::Decode;
using vtrack::lcm_util::DecodeError;
using vtrack::testing::BinDir;
using vtrack::testing::ReadFile;
using vtrack::testing::RunCommand;
using vtrack::testing::ScratchDir;

vtrack::testing::SyntheticSequence WriteSynthetic(const std::string& dir) {
  vtrack::testing::SyntheticSequence s;
  s.dir = dir;
  s.num_frames = 6;
  vtrack::testing::SyntheticObject car;
  car.id = 4;
  car.x0 = 15.0; car.y0 = 2.0; car.vx = 3.0;
  s.objects = {car};
  s.Write();
  return s;
}

// Writes the synthetic sequence into a fresh scratch directory; returns the options that read it.
SequenceOptions WriteSyntheticOptions(const std::string& scratch_name) {
  SequenceOptions so;
  so.dir = ScratchDir(scratch_name);
  WriteSynthetic(so.dir);
  so.poses_file = so.dir + "/poses.txt";
  so.sink = [](const std::string&) {};
  return so;
}

struct Event {
  std::int64_t timestamp;
  std::string channel;
  std::int64_t utime;
  std::int64_t seq = -1;  // scan seq / truth scan_seq
};

// Decodes one event as a Msg with the checked decoder (a failure is reported, not fatal).
template <typename Msg>
Msg DecodeEvent(const lcm::LogEvent& ev) {
  Msg m;
  EXPECT_EQ(Decode(ev.data, static_cast<std::size_t>(ev.datalen), &m), DecodeError::kNone);
  return m;
}

// Reads every event, decodes it with the checked decoder, and returns them in file order.
std::vector<Event> ReadLog(const std::string& path) {
  vtrack::lcm_util::LogReader reader(path);
  std::vector<Event> events;
  while (const lcm::LogEvent* ev = reader.Next()) {
    Event e{ev->timestamp, ev->channel, 0};
    if (e.channel == "LADAR_SCAN") {
      const auto m = DecodeEvent<vtrack::ladar_scan_t>(*ev);
      e.utime = m.utime;
      e.seq = m.seq;
    } else if (e.channel == "EGO_POSE") {
      e.utime = DecodeEvent<vtrack::pose_t>(*ev).utime;
    } else if (e.channel == "GROUND_TRUTH") {
      const auto m = DecodeEvent<vtrack::object_list_t>(*ev);
      e.utime = m.utime;
      e.seq = m.scan_seq;
    } else if (e.channel == "DETECTIONS") {
      const auto m = DecodeEvent<vtrack::detection_list_t>(*ev);
      e.utime = m.utime;
      e.seq = m.seq;
    } else {
      ADD_FAILURE() << "unexpected channel " << e.channel;
    }
    events.push_back(e);
  }
  return events;
}

TEST(KittiConvertTest, SyntheticLogHasEveryChannelInTimeOrder) {
  const SequenceOptions so = WriteSyntheticOptions("kitti_convert");
  const Sequence seq(so);
  ConvertOptions co;
  co.out = so.dir + "/out.lcm";
  int progress_calls = 0;
  const auto stats = ConvertSequence(seq, co, [&](int done, int total, std::int64_t) {
    ++progress_calls;
    EXPECT_EQ(total, 6);
    EXPECT_EQ(done, progress_calls);
  });
  EXPECT_EQ(progress_calls, 6);
  EXPECT_FALSE(fs::exists(co.out + ".partial"));
  const auto events = ReadLog(co.out);

  std::map<std::string, int> count;
  for (const auto& e : events) ++count[e.channel];
  // Poses every 10 ms over [start of sweep 0, end of sweep 5] = 600 ms: 61 poses.
  EXPECT_EQ(count["EGO_POSE"], (seq.LastPoseUtime() - seq.FirstPoseUtime()) / 10'000 + 1);
  EXPECT_EQ(count["EGO_POSE"], 61);
  EXPECT_EQ(count["LADAR_SCAN"], 6);
  EXPECT_EQ(count["GROUND_TRUTH"], 6);
  EXPECT_EQ(stats.poses, 61);
  EXPECT_EQ(stats.truth_objects, 6);

  // Log timestamps are the messages' utimes, non-decreasing; pose before scan before truth at
  // equal times; each truth follows its scan; each scan's sweep is covered by poses.
  std::int64_t last_pose = -1;
  for (std::size_t k = 0; k < events.size(); ++k) {
    const Event& e = events[k];
    EXPECT_EQ(e.timestamp, e.utime) << e.channel;
    if (k > 0) {
      EXPECT_GE(e.timestamp, events[k - 1].timestamp);
    }
    if (e.channel == "EGO_POSE") last_pose = e.utime;
    if (e.channel == "LADAR_SCAN") {
      EXPECT_EQ(last_pose, e.utime) << "no pose at the start of scan " << e.seq;
      ASSERT_LT(k + 1, events.size());
      EXPECT_EQ(events[k + 1].channel, "GROUND_TRUTH");
      EXPECT_EQ(events[k + 1].seq, e.seq);
      EXPECT_EQ(e.utime, seq.ScanUtime(static_cast<int>(e.seq)));
    }
  }
  EXPECT_EQ(last_pose, seq.LastPoseUtime());
}

// --out through a symbolic link writes the file the link names (the link stays); a special file
// such as /dev/null is written directly, not replaced by a moved file; a directory is refused
// before anything is converted.
TEST(KittiConvertTest, OutputThroughLinksAndSpecialFilesIsWrittenNotReplaced) {
  const SequenceOptions so = WriteSyntheticOptions("kitti_convert_out");
  const Sequence seq(so);
  ConvertOptions co;
  co.out = so.dir + "/direct.lcm";
  const ConvertStats direct = ConvertSequence(seq, co, nullptr);
  EXPECT_EQ(direct.bytes, static_cast<std::int64_t>(fs::file_size(co.out)));

  fs::create_directories(so.dir + "/logs");
  fs::create_symlink("logs/target.lcm", so.dir + "/link.lcm");
  co.out = so.dir + "/link.lcm";
  const ConvertStats linked = ConvertSequence(seq, co, nullptr);
  EXPECT_TRUE(fs::is_symlink(fs::symlink_status(so.dir + "/link.lcm")));
  ASSERT_TRUE(fs::is_regular_file(so.dir + "/logs/target.lcm"));
  EXPECT_EQ(static_cast<std::int64_t>(fs::file_size(so.dir + "/logs/target.lcm")), linked.bytes);
  EXPECT_EQ(linked.bytes, direct.bytes);
  EXPECT_FALSE(fs::exists(so.dir + "/logs/target.lcm.partial"));
  EXPECT_FALSE(fs::exists(so.dir + "/link.lcm.partial"));

  co.out = "/dev/null";
  EXPECT_EQ(ConvertSequence(seq, co, nullptr).bytes, direct.bytes);
  EXPECT_TRUE(fs::is_character_file("/dev/null"));
  EXPECT_FALSE(fs::exists("/dev/null.partial"));

  co.out = so.dir + "/logs";
  try {
    ConvertSequence(seq, co, nullptr);
    ADD_FAILURE() << "a directory as --out was accepted";
  } catch (const KittiError& e) {
    EXPECT_NE(std::string(e.what()).find("is a directory"), std::string::npos) << e.what();
  }
  EXPECT_TRUE(fs::is_directory(so.dir + "/logs"));
  EXPECT_FALSE(fs::exists(so.dir + "/logs.partial"));
}
// Without scans (--no-scans) a raw sequence is written as the boxes layout is: no LADAR_SCAN,
// the ground truth stamped with each frame's time (half a sweep after the scan's start).
TEST(KittiConvertTest, NoScansStampsTheTruthWithTheFrameTime) {
  SequenceOptions so = WriteSyntheticOptions("kitti_convert_no_scans");
  so.no_scans = true;
  const Sequence seq(so);
  EXPECT_FALSE(seq.has_scans());
  ConvertOptions co;
  co.out = so.dir + "/out.lcm";
  ConvertSequence(seq, co, nullptr);
  std::map<std::string, int> count;
  for (const auto& e : ReadLog(co.out)) {
    ++count[e.channel];
    if (e.channel == "GROUND_TRUTH") {
      EXPECT_EQ(e.utime, seq.FrameUtime(static_cast<int>(e.seq)));
      EXPECT_NE(e.utime, seq.ScanUtime(static_cast<int>(e.seq)));
    }
  }
  EXPECT_EQ(count["LADAR_SCAN"], 0);
  EXPECT_EQ(count["GROUND_TRUTH"], 6);
}

// At a rate whose period does not divide the frame period, every frame still has its own pose.
TEST(KittiConvertTest, EveryFrameHasItsPoseAtAnyRate) {
  const SequenceOptions so = WriteSyntheticOptions("kitti_convert_rate");
  const Sequence seq(so);
  ConvertOptions co;
  co.out = so.dir + "/out.lcm";
  co.pose_period_us = 30'000;
  co.first_frame = 1;
  co.num_frames = 3;
  co.ground_truth = false;
  ConvertSequence(seq, co);
  std::set<std::int64_t> pose_times;
  int scans = 0, truths = 0;
  for (const auto& e : ReadLog(co.out)) {
    if (e.channel == "EGO_POSE") pose_times.insert(e.utime);
    scans += e.channel == "LADAR_SCAN";
    truths += e.channel == "GROUND_TRUTH";
  }
  EXPECT_EQ(scans, 3);
  EXPECT_EQ(truths, 0);
  for (int i = 1; i <= 3; ++i) EXPECT_TRUE(pose_times.count(seq.FrameUtime(i))) << "frame " << i;
  EXPECT_EQ(*pose_times.begin(), seq.ScanUtime(1));
  EXPECT_GE(*pose_times.rbegin(), seq.ScanUtime(3) + 90'000);

  ConvertOptions bad = co;
  bad.first_frame = 6;
  EXPECT_THROW(ConvertSequence(seq, bad), KittiError);
  bad = co;
  bad.pose_period_us = 10;
  EXPECT_NE(bad.Validate().find("pose_period_us"), std::string::npos);
}

std::string Tool() { return BinDir() + "/vtrack-kitti2lcm"; }

// Runs the tool; returns (exit status, its output).
std::pair<int, std::string> RunTool(const std::vector<std::string>& args, const std::string& scratch) {
  std::vector<std::string> argv = {Tool()};
  argv.insert(argv.end(), args.begin(), args.end());
  const std::string log = scratch + "/tool_output.txt";
  const int rc = RunCommand(argv, log);
  return {rc, ReadFile(log)};
}

TEST(KittiConvertToolTest, HelpAndBadOptions) {
  const std::string dir = ScratchDir("kitti_tool_opts");
  WriteSynthetic(dir);
  auto [rc, out] = RunTool({"--help"}, dir);
  EXPECT_EQ(rc, 0);
  for (const char* opt : {"--kitti", "--sequence", "--out", "--poses", "--oxts", "--cache-dir"}) {
    EXPECT_NE(out.find(opt), std::string::npos) << opt;
  }
  std::tie(rc, out) = RunTool({"--kitti", dir}, dir);
  EXPECT_EQ(rc, 2);
  EXPECT_NE(out.find("out"), std::string::npos) << out;
  std::tie(rc, out) = RunTool({"--kitti", dir, "--out", dir + "/x.lcm", "--pose-rate", "5"}, dir);
  EXPECT_EQ(rc, 2);
  EXPECT_NE(out.find("--pose-rate"), std::string::npos) << out;
  std::tie(rc, out) = RunTool({"--kitti", dir, "--out", dir + "/x.lcm", "--bogus"}, dir);
  EXPECT_EQ(rc, 2);
  EXPECT_NE(out.find("bogus"), std::string::npos) << out;
}

TEST(KittiConvertToolTest, ClearErrorsForMissingAndBadData) {
  const std::string dir = ScratchDir("kitti_tool_errors");
  WriteSynthetic(dir);
  const std::string out_file = dir + "/out.lcm";
  auto [rc, out] = RunTool({"--kitti", dir + "/absent", "--out", out_file}, dir);
  EXPECT_EQ(rc, 1);
  EXPECT_NE(out.find(dir + "/absent does not exist"), std::string::npos) << out;
  // A file where the folder should be, and a folder where the poses file should be: said.
  std::tie(rc, out) = RunTool({"--kitti", dir + "/poses.txt", "--out", out_file}, dir);
  EXPECT_EQ(rc, 1);
  EXPECT_NE(out.find(dir + "/poses.txt is a file, not a directory"), std::string::npos) << out;
  std::tie(rc, out) = RunTool({"--kitti", dir, "--out", out_file, "--poses", dir + "/calib"}, dir);
  EXPECT_EQ(rc, 1);
  EXPECT_NE(out.find(dir + "/calib is a directory, not a file"), std::string::npos) << out;
  std::tie(rc, out) = RunTool({"--kitti", dir, "--sequence", "7", "--out", out_file, "--poses", dir + "/poses.txt"}, dir);
  EXPECT_EQ(rc, 1);
  EXPECT_NE(out.find("sequence 0007 not found"), std::string::npos) << out;
  // A corrupt calibration value: the message names the file, the line and the value.
  std::ofstream(dir + "/calib/0000.txt") << "P2: 700 0 600 0 0 700 170 0 0 0 1 0\nR0_rect: 1 0 0 0 1 0 0 0 one\n";
  std::tie(rc, out) = RunTool({"--kitti", dir, "--out", out_file, "--poses", dir + "/poses.txt"}, dir);
  EXPECT_EQ(rc, 1);
  EXPECT_NE(out.find(dir + "/calib/0000.txt:2"), std::string::npos) << out;
  EXPECT_NE(out.find("'one'"), std::string::npos) << out;
  EXPECT_FALSE(fs::exists(out_file));
  // An output folder that does not exist.
  WriteSynthetic(dir);
  std::tie(rc, out) = RunTool({"--kitti", dir, "--out", dir + "/no/such/dir/out.lcm", "--poses", dir + "/poses.txt"}, dir);
  EXPECT_EQ(rc, 1);
  EXPECT_NE(out.find(dir + "/no/such/dir/out.lcm"), std::string::npos) << out;
  // And a good run, to be sure the errors above were about the data.
  std::tie(rc, out) = RunTool({"--kitti", dir, "--out", out_file, "--poses", dir + "/poses.txt"}, dir);
  EXPECT_EQ(rc, 0) << out;
  EXPECT_NE(out.find("6 scans"), std::string::npos) << out;
  EXPECT_TRUE(fs::exists(out_file));
}

// The real sequence: three frames through the process; the scans hold exactly the returns of the
// .bin files (counted from their sizes), the truth lists hold the labelled objects.
TEST(KittiConvertToolTest, RealSequenceFrames) {
  const std::string kitti = vtrack::testing::KittiDir();
  if (kitti.empty()) GTEST_SKIP() << "KITTI data not found (../shared/data/kitti_tracking_0000): skipped";
  const std::string dir = ScratchDir("kitti_tool_real");
  const std::string cache = BinDir() + "/../kitti_cache";
  const std::string out_file = dir + "/kitti.lcm";
  auto [rc, out] = RunTool({"--kitti", kitti, "--sequence", "0000", "--out", out_file, "--cache-dir", cache,
                            "--first-frame", "10", "--num-frames", "3"}, dir);
  ASSERT_EQ(rc, 0) << out;
  EXPECT_NE(out.find("frame 3/3"), std::string::npos) << out;  // progress output

  SequenceOptions so;
  so.dir = kitti;
  so.cache_dir = cache;
  so.sink = [](const std::string&) {};
  const Sequence seq(so);
  vtrack::lcm_util::LogReader reader(out_file);
  int scans = 0, poses = 0, truths = 0;
  while (const lcm::LogEvent* ev = reader.Next()) {
    if (ev->channel == "LADAR_SCAN") {
      vtrack::ladar_scan_t m;
      ASSERT_EQ(Decode(ev->data, static_cast<std::size_t>(ev->datalen), &m), DecodeError::kNone);
      char name[32];
      std::snprintf(name, sizeof(name), "/%06d.bin", static_cast<int>(m.seq));
      const auto bytes = fs::file_size(seq.paths().velodyne_dir + name);
      EXPECT_EQ(static_cast<std::uintmax_t>(m.npoints) * 16, bytes);
      EXPECT_EQ(m.seq, 10 + scans);
      ++scans;
    } else if (ev->channel == "EGO_POSE") {
      ++poses;
    } else if (ev->channel == "GROUND_TRUTH") {
      vtrack::object_list_t m;
      ASSERT_EQ(Decode(ev->data, static_cast<std::size_t>(ev->datalen), &m), DecodeError::kNone);
      EXPECT_GE(m.num_objects, 3);
      for (const auto& o : m.objects) EXPECT_GT(o.num_points, 0) << "frame " << m.scan_seq << " id " << o.id;
      ++truths;
    }
  }
  EXPECT_EQ(scans, 3);
  EXPECT_EQ(truths, 3);
  EXPECT_EQ(poses, 31);  // 300 ms of sweeps at 100 Hz, both ends included
}

// The boxes layout (no point clouds) of sequence 0000: no scans; ground truth, detections and a
// pose at every frame's time. The PointRCNN boxes, placed in the world through the calibration
// and the ORB-SLAM3 camera poses, fall on the labels (placed through the same chain by the label
// conversion, an independent reading of the same files): the median distance from a labelled car
// to the nearest box of its frame is under 0.5 m (an error in the yaw or axis conventions of
// either would put them metres apart), and a parked car's label stays within 1 m of its place in
// the first frame over the whole sequence under the estimated poses.
TEST(KittiConvertToolTest, BoxesLayoutDetectionsFallOnTheLabels) {
  const std::string data = vtrack::testing::DataDir() + "/kitti_tracking_boxes";
  if (!fs::is_directory(data)) GTEST_SKIP() << data << " not found: skipped";
  const std::string dir = ScratchDir("kitti_tool_boxes");
  const std::string out_file = dir + "/boxes.lcm";
  // --poses asks for the raw layout's point clouds, which this layout has not: said so.
  auto [rc, out] = RunTool({"--kitti", data, "--sequence", "0000", "--out", out_file, "--poses",
                            data + "/ego_pose_orbslam3/0000.txt"}, dir);
  EXPECT_EQ(rc, 1) << out;
  EXPECT_NE(out.find("need the raw layout's point clouds"), std::string::npos) << out;
  std::tie(rc, out) = RunTool({"--kitti", data, "--sequence", "0000", "--out", out_file}, dir);
  ASSERT_EQ(rc, 0) << out;
  std::map<std::int64_t, vtrack::object_list_t> truth;
  std::map<std::int64_t, vtrack::detection_list_t> boxes;
  std::set<std::int64_t> pose_times;
  vtrack::lcm_util::LogReader reader(out_file);
  while (const lcm::LogEvent* ev = reader.Next()) {
    const auto size = static_cast<std::size_t>(ev->datalen);
    ASSERT_NE(ev->channel, "LADAR_SCAN");
    if (ev->channel == "GROUND_TRUTH") {
      vtrack::object_list_t m;
      ASSERT_EQ(Decode(ev->data, size, &m), DecodeError::kNone);
      truth[m.utime] = m;
    } else if (ev->channel == "DETECTIONS") {
      vtrack::detection_list_t m;
      ASSERT_EQ(Decode(ev->data, size, &m), DecodeError::kNone);
      boxes[m.utime] = m;
    } else if (ev->channel == "EGO_POSE") {
      vtrack::pose_t m;
      ASSERT_EQ(Decode(ev->data, size, &m), DecodeError::kNone);
      pose_times.insert(m.utime);
    }
  }
  ASSERT_EQ(truth.size(), 154u);
  ASSERT_EQ(boxes.size(), 154u);
  // Boxes are in the body frame: the pose of their time places them. Here the check needs the
  // pose itself, so the poses are read again with their values.
  std::map<std::int64_t, Eigen::Isometry3d> pose_at;
  vtrack::lcm_util::LogReader again(out_file);
  while (const lcm::LogEvent* ev = again.Next()) {
    if (ev->channel != "EGO_POSE") continue;
    vtrack::pose_t m;
    ASSERT_EQ(Decode(ev->data, static_cast<std::size_t>(ev->datalen), &m), DecodeError::kNone);
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.linear() = Eigen::Quaterniond(m.orientation[0], m.orientation[1], m.orientation[2], m.orientation[3])
                     .toRotationMatrix();
    T.translation() = Eigen::Vector3d(m.pos[0], m.pos[1], m.pos[2]);
    pose_at[m.utime] = T;
  }
  std::vector<double> nearest;
  std::map<std::int64_t, std::vector<Eigen::Vector2d>> track_xy;
  for (const auto& [t, list] : truth) {
    ASSERT_TRUE(boxes.count(t)) << "no detections at the truth's time " << t;
    ASSERT_TRUE(pose_at.count(t)) << "no pose at frame time " << t;
    const Eigen::Isometry3d& T = pose_at.at(t);
    for (const auto& o : list.objects) {
      if (o.object_class != vtrack::object_t::CLASS_CAR) continue;
      track_xy[o.id].emplace_back(o.x, o.y);
      double best = 1e9;
      for (const auto& d : boxes.at(t).detections) {
        // The box's bottom centre, lifted to its middle (the label's x, y is the box centre).
        const Eigen::Vector3d w = T * Eigen::Vector3d(d.x, d.y, d.z);
        best = std::min(best, std::hypot(w.x() - o.x, w.y() - o.y));
      }
      nearest.push_back(best);
    }
  }
  ASSERT_GT(nearest.size(), 200u);  // 243 car labels in the 154 frames
  std::nth_element(nearest.begin(), nearest.begin() + nearest.size() / 2, nearest.end());
  const double median = nearest[nearest.size() / 2];
  EXPECT_LT(median, 0.5);
  std::printf("boxes 0000: median label-to-nearest-box distance %.3f m over %zu labels\n", median,
              nearest.size());
  // The longest-seen car that moves least: its spread over the sequence.
  double best_spread = 1e9;
  std::size_t best_n = 0;
  for (const auto& [id, xy] : track_xy) {
    if (xy.size() < 20) continue;
    double spread = 0.0;
    for (const auto& p : xy) spread = std::max(spread, (p - xy.front()).norm());
    if (spread < best_spread) {
      best_spread = spread;
      best_n = xy.size();
    }
  }
  ASSERT_GT(best_n, 0u);
  EXPECT_LT(best_spread, 1.0);
  std::printf("boxes 0000: the stillest labelled car (%zu frames) stays within %.3f m\n", best_n,
              best_spread);
}

// Ctrl-C during a conversion: the tool stops, says so, and leaves neither the log nor its partial.
TEST(KittiConvertToolTest, InterruptLeavesNoPartialLog) {
  const std::string kitti = vtrack::testing::KittiDir();
  if (kitti.empty()) GTEST_SKIP() << "KITTI data not found (../shared/data/kitti_tracking_0000): skipped";
  const std::string dir = ScratchDir("kitti_tool_interrupt");
  const std::string out_file = dir + "/kitti.lcm";
  const std::string log = dir + "/tool_output.txt";
  vtrack::testing::Subprocess tool({Tool(), "--kitti", kitti, "--out", out_file, "--cache-dir",
                                    BinDir() + "/../kitti_cache"}, log);
  // Wait until the log is being written, then interrupt.
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (!fs::exists(out_file + ".partial") && std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  ASSERT_TRUE(fs::exists(out_file + ".partial")) << ReadFile(log);
  tool.Signal(SIGINT);
  const auto status = tool.Wait(std::chrono::seconds(30));
  ASSERT_TRUE(status.has_value());
  EXPECT_EQ(*status, 1) << ReadFile(log);
  EXPECT_NE(ReadFile(log).find("interrupted after frame"), std::string::npos) << ReadFile(log);
  EXPECT_FALSE(fs::exists(out_file));
  EXPECT_FALSE(fs::exists(out_file + ".partial"));
}

}  // namespace
}  // namespace vtrack::kitti
