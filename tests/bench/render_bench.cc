// Speed of the renderer's stages for one 1280x960 frame: drawing a busy scene, building a scene
// from a 64-layer 120k-point scan (motion compensation + ground removal, the tracker's own code),
// decoding that scan, and encoding the frame to MP4 / PNG. Seeded synthetic data.
#include <benchmark/benchmark.h>

#include <opencv2/imgcodecs.hpp>

#include <cmath>
#include <filesystem>
#include <random>

#include "lcmtypes/util/decode.h"
#include "base/angle.h"
#include "viewer/frame_assembler.h"
#include "viewer/frame_output.h"
#include "viewer/renderer.h"
#include "viewer/scene_builder.h"

namespace vtrack::viewer {
namespace {

constexpr std::int64_t kT0 = 1'600'000'000'000'000;

// A busy street: 20k points, 40 tracks (a third of them clutter) with debug entries, paths,
// predictions and ground truth, around an ego vehicle at the origin.
Scene BusyScene() {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-60.0, 60.0), a(-kPi, kPi);
  Scene s;
  s.utime = kT0;
  for (int i = 0; i < 20000; ++i) s.points.emplace_back(u(rng), u(rng));
  SceneEgo ego;
  ego.box.length = 4.5;
  ego.box.width = 1.8;
  for (int i = 0; i < 100; ++i) ego.past.emplace_back(-0.2 * i, 0.0);
  s.ego = ego;
  for (int id = 0; id < 40; ++id) {
    SceneTrack t;
    t.id = id;
    t.object_class = id % 3 == 0 ? TrackClass::kOther : TrackClass::kVehicle;
    t.model = id % 2 ? MotionModel::kVasm : MotionModel::kIsm;
    t.moving = id % 4 == 1;
    t.box.center = {u(rng), u(rng)};
    t.box.theta = a(rng);
    t.box.length = 4.5;
    t.box.width = 1.9;
    t.cov.topLeftCorner<2, 2>() << 0.05, 0.01, 0.01, 0.03;
    t.rear_axle_offset = t.model == MotionModel::kVasm ? -1.3 : kNaN;
    t.num_hypotheses = t.moving ? 4 : 1;
    for (int k = 0; k < 100; ++k) t.past.push_back(t.box.center - 0.1 * k * t.box.Axis());
    for (int k = 1; k <= 30; ++k) t.predicted.push_back(t.box.center + 0.1 * k * t.box.Axis());
    SceneMeasurement m;
    m.track_id = id;
    m.fit_kind = FitKind::kCorner;
    m.z_box = t.box;
    m.R.topLeftCorner<2, 2>() << 0.02, 0.0, 0.0, 0.02;
    const auto c = t.box.Corners();
    m.edges = {{c[1], c[2]}, {c[2], c[3]}};
    for (int k = 0; k < 60; ++k) m.points.push_back((c[2] + (c[3] - c[2]) * k / 60.0).cast<float>());
    for (int h = 0; h < t.num_hypotheses; ++h) {
      SceneHypothesis hyp;
      hyp.index = h;
      hyp.model = h == 0 ? MotionModel::kIsm : MotionModel::kVasm;
      hyp.selected = h == 0;
      hyp.box = t.box;
      hyp.box.theta += 0.05 * h;
      hyp.rear_axle_offset = -1.0 - 0.2 * h;
      m.hypotheses.push_back(hyp);
    }
    s.tracks.push_back(t);
    s.measurements.push_back(m);
    SceneTruth g;
    g.id = id;
    g.box = t.box;
    g.path = t.past;
    s.truths.push_back(g);
  }
  return s;
}

void BM_RenderBusyScene(benchmark::State& state) {
  const Scene scene = BusyScene();
  RenderParams p;
  p.show_hypotheses = state.range(0) != 0;
  cv::Mat image;
  for (auto _ : state) {
    Render(scene, p, MakeView(p, scene), &image);
    benchmark::DoNotOptimize(image.data);
  }
}
BENCHMARK(BM_RenderBusyScene)->Arg(0)->Arg(1)->ArgName("hypotheses")->Unit(benchmark::kMillisecond);

// A Velodyne-like sweep: 64 rings x 1875 azimuths over 100 ms, ground at -1.7 m and walls.
vtrack::ladar_scan_t VelodyneScan() {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> range(3.0, 60.0);
  vtrack::ladar_scan_t s{};
  s.utime = kT0;
  s.sensor_id = "velodyne";
  s.sensor_pos[2] = 1.7;
  s.sensor_orientation[0] = 1.0;
  s.sweep_duration_us = 100'000;
  s.max_range = 120.0f;
  s.num_rings = 64;
  for (int az = 0; az < 1875; ++az) {
    const double yaw = 2.0 * kPi * az / 1875.0;
    for (int ring = 0; ring < 64; ++ring) {
      const double pitch = -0.43 + 0.0072 * ring;
      double r = range(rng);
      if (pitch < 0.0) r = std::min(r, 1.7 / std::sin(-pitch));
      s.x.push_back(static_cast<float>(r * std::cos(pitch) * std::cos(yaw)));
      s.y.push_back(static_cast<float>(r * std::cos(pitch) * std::sin(yaw)));
      s.z.push_back(static_cast<float>(r * std::sin(pitch)));
      s.intensity.push_back(0.3f);
      s.dt_us.push_back(static_cast<std::int32_t>(az * 100'000 / 1875));
      s.ring.push_back(static_cast<std::int16_t>(ring));
    }
  }
  s.npoints = static_cast<std::int32_t>(s.x.size());
  return s;
}

FrameInputs VelodyneFrame() {
  FrameInputs f;
  f.utime = f.time_origin_utime = kT0;
  f.scans.push_back(std::make_shared<const vtrack::ladar_scan_t>(VelodyneScan()));
  for (std::int64_t t = kT0 - 100'000; t <= kT0 + 200'000; t += 10'000) {
    Eigen::Isometry3d m = Eigen::Isometry3d::Identity();
    m.translation().x() = 10.0 * 1e-6 * static_cast<double>(t - kT0);
    m.linear() = Eigen::AngleAxisd(0.2 * 1e-6 * static_cast<double>(t - kT0),
                                   Eigen::Vector3d::UnitZ()).toRotationMatrix();
    f.poses.Add(t, m);
  }
  return f;
}

void BM_BuildSceneVelodyne(benchmark::State& state) {
  const FrameInputs f = VelodyneFrame();
  SceneBuilder builder{SceneParams{}};
  std::size_t points = 0;
  for (auto _ : state) {
    const Scene s = builder.Build(f);
    points = s.points.size();
    benchmark::DoNotOptimize(points);
  }
  state.counters["input_points"] = static_cast<double>(f.scans[0]->npoints);
  state.counters["drawn_points"] = static_cast<double>(points);
}
BENCHMARK(BM_BuildSceneVelodyne)->Unit(benchmark::kMillisecond);

void BM_DecodeVelodyneScan(benchmark::State& state) {
  const vtrack::ladar_scan_t scan = VelodyneScan();
  std::vector<std::uint8_t> buf(static_cast<std::size_t>(scan.getEncodedSize()));
  scan.encode(buf.data(), 0, static_cast<int>(buf.size()));
  for (auto _ : state) {
    vtrack::ladar_scan_t out;
    benchmark::DoNotOptimize(lcm_util::Decode(buf.data(), buf.size(), &out));
  }
  state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations() * buf.size()));
}
BENCHMARK(BM_DecodeVelodyneScan)->Unit(benchmark::kMillisecond);

// Encoding cost per frame of the busy scene: MP4 (mp4v) and PNG.
void BM_EncodeFrame(benchmark::State& state) {
  const cv::Mat image = Render(BusyScene(), RenderParams{});
  const auto dir = std::filesystem::temp_directory_path() / "vtrack-render-bench";
  std::filesystem::create_directories(dir);
  OutputParams p;
  if (state.range(0) == 0) {
    p.video_path = (dir / "bench.mp4").string();
    p.fps = 10.0;
  } else {
    p.png_dir = dir.string();
    p.png_every = 1;
  }
  FrameOutput out(p);
  std::int64_t i = 0;
  for (auto _ : state) {
    out.Write(image, kT0 + 100'000 * i, 0.1 * static_cast<double>(i));
    ++i;
  }
  out.Close();
  std::filesystem::remove_all(dir);
}
BENCHMARK(BM_EncodeFrame)->Arg(0)->Arg(1)->ArgName("png")->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace vtrack::viewer

BENCHMARK_MAIN();
