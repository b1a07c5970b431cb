// A peer in the same run: the tracker's grid segmentation (Segmenter, 3-D clouds) against PCL's
// Euclidean cluster extraction (pcl::EuclideanClusterExtraction with a k-d tree; Debian's
// libpcl-dev, an optional benchmark dependency: this program is built only if CMake finds PCL).
//
// Input: KITTI sequence 0000 frames 11-40, preprocessed by the tracker (ego-motion compensated,
// ground removed) with the shipped configuration; both clusterers get the same kept returns in
// the ground plane (z = 0; the tracker segments in 2-D), relative to the sensor.
// Same tolerance: PCL joins returns closer than cell_size (0.3 m), the grid joins returns in
// 4-adjacent cells of cell_size; both keep clusters of at least min_points returns (PCL's size
// filter; the grid's max_extent filter is switched off here so that both partitions cover the
// same returns).
// Times: BM_Segmentation_Grid (Segmenter::Run), BM_Segmentation_PclEuclidean (k-d tree build +
// extraction; the conversion to a pcl::PointCloud is done before timing).
// Agreement (counters of BM_Segmentation_PclEuclidean): the adjusted Rand index of the two
// partitions over the returns both keep (1 = identical, 0 = chance), and the share of the
// tracker's segments whose returns' majority PCL cluster covers them with IoU >= 0.5.
//
// Whole pipelines on the same raw sweeps (frames 11-40, the sensor's returns as recorded), one
// thread, CPU time per sweep:
//  - BM_Pipeline_PclVoxelEuclidean: what a PCL user would build to find objects: VoxelGrid
//    (0.2 m leaves), the ground cut by a PassThrough on height (kept: 0.3-3 m above the road,
//    KITTI's sensor is 1.73 m above it), Euclidean cluster extraction (0.5 m, >= 10 returns);
//    no tracking, no ego-motion compensation;
//  - BM_Pipeline_VtrackTracker: vtrack's whole tracker (Tracker::AddScan: compensation, ground,
//    segmentation, association, fits, filters, hypotheses, evidence, report), after 10 frames
//    of warm-up.
#include <benchmark/benchmark.h>

#include <pcl/filters/passthrough.h>
#include <pcl/filters/voxel_grid.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>
#include <pcl/search/kdtree.h>
#include <pcl/segmentation/extract_clusters.h>

#include <time.h>

#include <cstdint>
#include <memory>
#include <unordered_map>
#include <vector>

#include "tests/bench/bench_data.h"

namespace {

using namespace vtrack;

double ThreadCpuSeconds() {
  timespec ts;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

struct Frame {
  WorldPoints points;
  Eigen::Vector2d sensor_xy;
  pcl::PointCloud<pcl::PointXYZ>::Ptr cloud;
};

SegmentationParams GridParams() {
  SegmentationParams p = bench::ShippedParams().segmentation;
  p.max_extent = 1e9;  // no extent filter: compare the partitions
  return p;
}

const std::vector<Frame>& Frames(std::string* error) {
  static std::string err;
  static const std::vector<Frame> frames = [] {
    std::vector<Frame> v;
    const bench::Sequence& seq = bench::Kitti();
    if (!seq.error.empty()) {
      err = seq.error;
      return v;
    }
    const TrackerParams params = bench::ShippedParams();
    Preprocessor pre(params.preprocess);
    const PoseHistory poses = bench::AllPoses(seq);
    for (std::size_t i = 10; i < std::min<std::size_t>(40, seq.scans.size()); ++i) {
      Frame f;
      f.sensor_xy = pre.Run(seq.scans[i], poses, 0, &f.points).sensor_xy;
      f.cloud.reset(new pcl::PointCloud<pcl::PointXYZ>);
      f.cloud->reserve(f.points.size());
      for (std::size_t k = 0; k < f.points.size(); ++k) {
        f.cloud->push_back(pcl::PointXYZ(static_cast<float>(f.points.x[k] - f.sensor_xy.x()),
                                         static_cast<float>(f.points.y[k] - f.sensor_xy.y()), 0.0f));
      }
      v.push_back(std::move(f));
    }
    return v;
  }();
  *error = err;
  return frames;
}

// Frames() for a benchmark: when there are none, the benchmark is skipped, saying why.
const std::vector<Frame>& FramesOrSkip(benchmark::State& state) {
  std::string error;
  const auto& frames = Frames(&error);
  if (frames.empty()) state.SkipWithError(error.c_str());
  return frames;
}

void BM_Segmentation_Grid(benchmark::State& state) {
  const auto& frames = FramesOrSkip(state);
  if (frames.empty()) return;
  Segmenter seg(GridParams());
  Segments out;
  std::size_t i = 0;
  double clusters = 0, points = 0;
  for (auto _ : state) {
    const Frame& f = frames[i];
    const double c0 = ThreadCpuSeconds();
    seg.Run(f.points, false, f.sensor_xy, &out);
    state.SetIterationTime(ThreadCpuSeconds() - c0);
    clusters += static_cast<double>(out.segments.size());
    points += static_cast<double>(f.points.size());
    i = (i + 1) % frames.size();
  }
  state.counters["clusters"] = benchmark::Counter(clusters, benchmark::Counter::kAvgIterations);
  state.counters["points"] = benchmark::Counter(points, benchmark::Counter::kAvgIterations);
}
BENCHMARK(BM_Segmentation_Grid)->UseManualTime()->Unit(benchmark::kMillisecond)->Iterations(60);

// Adjusted Rand index of two labelings (label < 0: not clustered; such returns are skipped).
double AdjustedRand(const std::vector<int>& a, const std::vector<int>& b) {
  std::unordered_map<std::int64_t, double> cells;
  std::unordered_map<int, double> rows, cols;
  double n = 0;
  for (std::size_t k = 0; k < a.size(); ++k) {
    if (a[k] < 0 || b[k] < 0) continue;
    cells[(static_cast<std::int64_t>(a[k]) << 32) | static_cast<std::uint32_t>(b[k])] += 1;
    rows[a[k]] += 1;
    cols[b[k]] += 1;
    n += 1;
  }
  auto c2 = [](double x) { return x * (x - 1) / 2; };
  double sum_cells = 0, sum_rows = 0, sum_cols = 0;
  for (const auto& [key, c] : cells) sum_cells += c2(c);
  for (const auto& [key, c] : rows) sum_rows += c2(c);
  for (const auto& [key, c] : cols) sum_cols += c2(c);
  const double expected = sum_rows * sum_cols / c2(n);
  const double max_index = 0.5 * (sum_rows + sum_cols);
  return max_index == expected ? 1.0 : (sum_cells - expected) / (max_index - expected);
}

void BM_Segmentation_PclEuclidean(benchmark::State& state) {
  const auto& frames = FramesOrSkip(state);
  if (frames.empty()) return;
  const SegmentationParams gp = GridParams();
  std::size_t i = 0;
  double clusters = 0, ari_sum = 0, matched_sum = 0, evaluated = 0;
  std::vector<pcl::PointIndices> found;
  Segmenter seg(gp);
  Segments ours;
  for (auto _ : state) {
    const Frame& f = frames[i];
    const double c0 = ThreadCpuSeconds();
    pcl::search::KdTree<pcl::PointXYZ>::Ptr tree(new pcl::search::KdTree<pcl::PointXYZ>);
    tree->setInputCloud(f.cloud);
    pcl::EuclideanClusterExtraction<pcl::PointXYZ> ec;
    ec.setClusterTolerance(gp.cell_size);
    ec.setMinClusterSize(gp.min_points);
    ec.setMaxClusterSize(std::numeric_limits<int>::max());
    ec.setSearchMethod(tree);
    ec.setInputCloud(f.cloud);
    found.clear();
    ec.extract(found);
    state.SetIterationTime(ThreadCpuSeconds() - c0);
    clusters += static_cast<double>(found.size());
    if (evaluated < static_cast<double>(frames.size())) {  // agreement: once per frame
      state.PauseTiming();
      std::vector<int> pcl_label(f.points.size(), -1), our_label(f.points.size(), -1);
      for (std::size_t c = 0; c < found.size(); ++c) {
        for (const int k : found[c].indices) pcl_label[static_cast<std::size_t>(k)] = static_cast<int>(c);
      }
      seg.Run(f.points, false, f.sensor_xy, &ours);
      std::vector<int> pcl_size(found.size());
      for (std::size_t c = 0; c < found.size(); ++c) pcl_size[c] = static_cast<int>(found[c].indices.size());
      int matched = 0;
      for (std::size_t s = 0; s < ours.segments.size(); ++s) {
        std::unordered_map<int, int> votes;
        for (std::int32_t k = ours.segments[s].begin; k < ours.segments[s].end; ++k) {
          const auto p = static_cast<std::size_t>(ours.point[static_cast<std::size_t>(k)]);
          our_label[p] = static_cast<int>(s);
          if (pcl_label[p] >= 0) ++votes[pcl_label[p]];
        }
        int best = -1, best_n = 0;
        for (const auto& [c, v] : votes) {
          if (v > best_n) best = c, best_n = v;
        }
        if (best >= 0) {
          const double uni = ours.segments[s].size() + pcl_size[static_cast<std::size_t>(best)] - best_n;
          matched += best_n / uni >= 0.5;
        }
      }
      ari_sum += AdjustedRand(our_label, pcl_label);
      matched_sum += ours.segments.empty() ? 1.0 : static_cast<double>(matched) / ours.segments.size();
      evaluated += 1;
      state.ResumeTiming();
    }
    i = (i + 1) % frames.size();
  }
  state.counters["clusters"] = benchmark::Counter(clusters, benchmark::Counter::kAvgIterations);
  state.counters["adjusted_rand"] = evaluated > 0 ? ari_sum / evaluated : 0.0;
  state.counters["segments_matched"] = evaluated > 0 ? matched_sum / evaluated : 0.0;
}
BENCHMARK(BM_Segmentation_PclEuclidean)->UseManualTime()->Unit(benchmark::kMillisecond)->Iterations(30);

// KITTI's frames as raw PCL clouds (sensor frame, every return), for the PCL pipeline.
const std::vector<pcl::PointCloud<pcl::PointXYZ>::Ptr>& RawClouds() {
  static const std::vector<pcl::PointCloud<pcl::PointXYZ>::Ptr> clouds = [] {
    std::vector<pcl::PointCloud<pcl::PointXYZ>::Ptr> v;
    const bench::Sequence& seq = bench::Kitti();
    for (std::size_t i = 10; seq.error.empty() && i < std::min<std::size_t>(40, seq.scans.size()); ++i) {
      const LadarScan& scan = seq.scans[i];
      pcl::PointCloud<pcl::PointXYZ>::Ptr c(new pcl::PointCloud<pcl::PointXYZ>);
      c->reserve(scan.size());
      for (std::size_t k = 0; k < scan.size(); ++k) c->push_back(pcl::PointXYZ(scan.x[k], scan.y[k], scan.z[k]));
      v.push_back(std::move(c));
    }
    return v;
  }();
  return clouds;
}

void BM_Pipeline_PclVoxelEuclidean(benchmark::State& state) {
  const auto& clouds = RawClouds();
  if (clouds.empty()) {
    state.SkipWithError(bench::Kitti().error.c_str());
    return;
  }
  constexpr float kLeaf = 0.2f, kTolerance = 0.5f;  // [m]
  constexpr float kSensorHeight = 1.73f;            // [m] KITTI's Velodyne above the road
  std::size_t i = 0;
  double clusters = 0, voxels = 0;
  pcl::PointCloud<pcl::PointXYZ>::Ptr down(new pcl::PointCloud<pcl::PointXYZ>);
  pcl::PointCloud<pcl::PointXYZ>::Ptr above(new pcl::PointCloud<pcl::PointXYZ>);
  std::vector<pcl::PointIndices> found;
  for (auto _ : state) {
    const double c0 = ThreadCpuSeconds();
    pcl::VoxelGrid<pcl::PointXYZ> grid;
    grid.setInputCloud(clouds[i]);
    grid.setLeafSize(kLeaf, kLeaf, kLeaf);
    grid.filter(*down);
    pcl::PassThrough<pcl::PointXYZ> cut;
    cut.setInputCloud(down);
    cut.setFilterFieldName("z");
    cut.setFilterLimits(0.3f - kSensorHeight, 3.0f - kSensorHeight);
    cut.filter(*above);
    pcl::search::KdTree<pcl::PointXYZ>::Ptr tree(new pcl::search::KdTree<pcl::PointXYZ>);
    tree->setInputCloud(above);
    pcl::EuclideanClusterExtraction<pcl::PointXYZ> ec;
    ec.setClusterTolerance(kTolerance);
    ec.setMinClusterSize(10);
    ec.setMaxClusterSize(std::numeric_limits<int>::max());
    ec.setSearchMethod(tree);
    ec.setInputCloud(above);
    found.clear();
    ec.extract(found);
    state.SetIterationTime(ThreadCpuSeconds() - c0);
    clusters += static_cast<double>(found.size());
    voxels += static_cast<double>(down->size());
    i = (i + 1) % clouds.size();
  }
  state.counters["clusters"] = benchmark::Counter(clusters, benchmark::Counter::kAvgIterations);
  state.counters["voxels"] = benchmark::Counter(voxels, benchmark::Counter::kAvgIterations);
}
BENCHMARK(BM_Pipeline_PclVoxelEuclidean)->UseManualTime()->Unit(benchmark::kMillisecond)->Iterations(30);

void BM_Pipeline_VtrackTracker(benchmark::State& state) {
  const bench::Sequence& seq = bench::Kitti();
  if (!seq.error.empty() || seq.scans.size() < 40) {
    state.SkipWithError(seq.error.empty() ? "sequence too short" : seq.error.c_str());
    return;
  }
  TrackerParams params = bench::ShippedParams();
  params.compute.threads = 1;
  std::unique_ptr<Tracker> tracker;
  std::vector<ScanOutput> out;
  std::size_t i = 40;
  double tracks = 0;
  for (auto _ : state) {
    if (i >= 40) {  // the same 30 frames each round, after the same warm-up
      state.PauseTiming();
      tracker = std::make_unique<Tracker>(params);
      for (i = 0; i < 10; ++i) {
        for (const auto& p : seq.poses_before[i]) tracker->AddPose(p, &out);
        LadarScan copy = seq.scans[i];
        tracker->AddScan(std::move(copy), &out);
      }
      state.ResumeTiming();
    }
    for (const auto& p : seq.poses_before[i]) tracker->AddPose(p, &out);
    LadarScan copy = seq.scans[i];
    out.clear();
    const double c0 = ThreadCpuSeconds();
    tracker->AddScan(std::move(copy), &out);
    state.SetIterationTime(ThreadCpuSeconds() - c0);
    if (!out.empty()) tracks += static_cast<double>(out.back().tracks.size());
    ++i;
  }
  state.counters["tracks"] = benchmark::Counter(tracks, benchmark::Counter::kAvgIterations);
}
BENCHMARK(BM_Pipeline_VtrackTracker)->UseManualTime()->Unit(benchmark::kMillisecond)->Iterations(30);

}  // namespace

BENCHMARK_MAIN();
