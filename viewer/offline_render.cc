#include "viewer/offline_render.h"

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <set>
#include <stdexcept>

#include "lcmtypes/util/decode.h"
#include "lcmtypes/util/process.h"
#include "viewer/log_merge.h"
#include "viewer/scene_builder.h"
#include "vtrack/ladar_slice_t.hpp"
#include "vtrack/object_list_t.hpp"

namespace vtrack::viewer {
namespace {

using Clock = std::chrono::steady_clock;

double Since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

// A progress bar on stderr: redrawn in place on a terminal (10 Hz), one line every 5 s otherwise
// (ctest, CI logs).
class ProgressBar {
 public:
  ProgressBar(std::string label, bool enabled)
      : label_(std::move(label)), enabled_(enabled), tty_(::isatty(2) == 1), start_(Clock::now()) {}

  void Update(double fraction, const std::string& detail) {
    if (!enabled_) return;
    const auto now = Clock::now();
    const auto interval = tty_ ? std::chrono::milliseconds(100) : std::chrono::milliseconds(5000);
    if (shown_ && now - last_ < interval) return;
    Print(fraction, detail);
  }

  void Done(const std::string& detail) {
    if (!enabled_) return;
    Print(1.0, detail);
    if (tty_) std::fputc('\n', stderr);
  }

 private:
  void Print(double fraction, const std::string& detail) {
    constexpr int kWidth = 30;
    fraction = std::clamp(fraction, 0.0, 1.0);
    const int filled = static_cast<int>(std::lround(fraction * kWidth));
    std::string bar(static_cast<std::size_t>(filled), '#');
    bar.resize(kWidth, '.');
    const double elapsed = Since(start_);
    char eta[32] = "";
    if (fraction > 0.01 && fraction < 1.0) {
      std::snprintf(eta, sizeof(eta), "  ETA %.0f s", elapsed / fraction - elapsed);
    }
    std::fprintf(stderr, "%s%s [%s] %3.0f%%  %s%s%s", tty_ ? "\r" : "", label_.c_str(),
                 bar.c_str(), 100.0 * fraction, detail.c_str(), eta, tty_ ? "\033[K" : "\n");
    std::fflush(stderr);
    shown_ = true;
    last_ = Clock::now();
  }

  std::string label_;
  bool enabled_;
  bool tty_;
  bool shown_ = false;
  Clock::time_point start_;
  Clock::time_point last_{};
};

std::string Join(const std::vector<std::string>& v, const char* sep) {
  std::string out;
  for (std::size_t i = 0; i < v.size(); ++i) out += (i ? sep : "") + v[i];
  return out;
}

std::string MegaBytes(std::int64_t bytes) {
  char buf[32];
  std::snprintf(buf, sizeof(buf), "%.0f MB", 1e-6 * static_cast<double>(bytes));
  return buf;
}

}  // namespace

std::int64_t LogIndex::Count(const std::string& channel) const {
  const auto it = events.find(channel);
  return it == events.end() ? 0 : it->second;
}

LogIndex IndexLogs(const std::vector<std::string>& paths, const Channels& channels,
                   bool progress) {
  LogIndex index;
  std::set<std::pair<std::string, std::int64_t>> sweeps;  // (sensor, seq) seen on the slice channel
  MergedLogReader reader(paths);
  ProgressBar bar("indexing ", progress);
  const std::int64_t total = std::max<std::int64_t>(1, reader.TotalBytes());
  while (const lcm::LogEvent* ev = reader.Next()) {
    if (lcm_util::StopRequested()) break;
    ++index.events[ev->channel];
    const std::size_t size = ev->datalen > 0 ? static_cast<std::size_t>(ev->datalen) : 0;
    if (ev->channel == channels.scan && index.first_scan_utime < 0) {
      vtrack::ladar_scan_t scan;
      if (lcm_util::Decode(ev->data, size, &scan) == lcm_util::DecodeError::kNone) {
        index.first_scan_utime = scan.utime;
      }
    } else if (ev->channel == channels.slice) {
      vtrack::ladar_slice_t slice;
      if (lcm_util::Decode(ev->data, size, &slice) != lcm_util::DecodeError::kNone) continue;
      if (index.first_scan_utime < 0) index.first_scan_utime = slice.utime;
      if (sweeps.insert({slice.sensor_id, slice.seq}).second) ++index.sliced_sweeps;
    } else if (ev->channel == channels.tracks && index.first_tracks_utime < 0) {
      vtrack::track_list_t tracks;
      if (lcm_util::Decode(ev->data, size, &tracks) == lcm_util::DecodeError::kNone) {
        index.first_tracks_utime = tracks.utime;
      }
    } else if (ev->channel == channels.truth) {
      vtrack::object_list_t truth;
      // A bad message is counted (and reported) by the rendering pass.
      if (lcm_util::Decode(ev->data, size, &truth) != lcm_util::DecodeError::kNone) continue;
      for (const auto& o : truth.objects) {
        if (std::isfinite(o.x) && std::isfinite(o.y)) {
          index.truth_paths[o.id].emplace_back(truth.utime, Eigen::Vector2d(o.x, o.y));
        }
      }
    }
    bar.Update(static_cast<double>(reader.BytesRead()) / static_cast<double>(total),
               MegaBytes(reader.BytesRead()) + " of " + MegaBytes(total));
  }
  bar.Done(MegaBytes(total) + ", " + std::to_string(index.Count(channels.scan) + index.sliced_sweeps) + " scans, " +
           std::to_string(index.Count(channels.tracks)) + " track lists");
  return index;
}

OfflineStats RenderLogs(const std::vector<std::string>& paths, const RenderJob& job,
                        FrameOutput* out, bool progress) {
  if (const std::string err = job.FirstProblem(); !err.empty()) throw std::invalid_argument(err);
  if (paths.empty()) throw std::invalid_argument("no input logs given");
  const auto t0 = Clock::now();
  LogIndex index = IndexLogs(paths, job.channels, progress);

  OfflineStats st;
  AssemblerParams ap = job.assembler;
  if (ap.trigger == AssemblerParams::Trigger::kAuto) {
    ap.trigger = index.Count(job.channels.tracks) > 0 ? AssemblerParams::Trigger::kTracks
                                                      : AssemblerParams::Trigger::kScans;
  }
  st.trigger = ap.trigger;
  const std::string& trigger_channel =
      ap.trigger == AssemblerParams::Trigger::kTracks ? job.channels.tracks : job.channels.scan;
  st.expected_frames = index.Count(trigger_channel);
  if (ap.trigger != AssemblerParams::Trigger::kTracks) st.expected_frames += index.sliced_sweeps;
  if (st.expected_frames == 0) {
    std::vector<std::string> seen;
    for (const auto& [channel, n] : index.events) seen.push_back(channel + " (" + std::to_string(n) + ")");
    throw std::runtime_error("nothing to render: no messages on " + trigger_channel + " in " +
                             Join(paths, ", ") + "; channels in the logs: " +
                             (seen.empty() ? std::string("none") : Join(seen, ", ")));
  }

  FrameAssembler assembler(ap);
  if (!index.truth_paths.empty()) assembler.SetTruthPaths(std::move(index.truth_paths));
  std::int64_t origin = -1;
  for (const std::int64_t t : {index.first_scan_utime, index.first_tracks_utime}) {
    if (t >= 0 && (origin < 0 || t < origin)) origin = t;
  }
  if (origin >= 0) assembler.SetTimeOrigin(origin);
  MessageRouter router(job.channels, &assembler);
  SceneBuilder builder(job.scene);
  MergedLogReader reader(paths);
  const double total = static_cast<double>(std::max<std::int64_t>(1, reader.TotalBytes()));
  ProgressBar bar("rendering", progress);
  const auto render_start = Clock::now();

  cv::Mat image;
  bool stop = false;
  auto handle = [&](std::vector<FrameInputs> frames) {
    for (const auto& f : frames) {
      if (stop) return;
      const double t = FrameTime(f);
      if (t > job.end_s) {
        stop = true;
        return;
      }
      if (t < job.start_s) {
        ++st.frames_skipped;
        continue;
      }
      const Scene scene = builder.Build(f);
      Render(scene, job.render, MakeView(job.render, scene), &image);
      out->Write(image, f.utime, scene.time_s);
      ++st.frames_rendered;
      if (job.max_frames > 0 && st.frames_rendered >= job.max_frames) stop = true;
    }
  };
  auto detail = [&] {
    const double secs = std::max(1e-3, Since(render_start));
    char buf[96];
    std::snprintf(buf, sizeof(buf), "%lld/%lld frames  %.1f frames/s",
                  static_cast<long long>(st.frames_rendered),
                  static_cast<long long>(st.expected_frames),
                  static_cast<double>(st.frames_rendered) / secs);
    return std::string(buf);
  };

  while (!stop && !lcm_util::StopRequested()) {
    const lcm::LogEvent* ev = reader.Next();
    if (!ev) break;
    ++st.events;
    router.Route(ev->channel, ev->data, ev->datalen > 0 ? static_cast<std::size_t>(ev->datalen) : 0);
    handle(assembler.TakeReady());
    bar.Update(static_cast<double>(reader.BytesRead()) / total, detail());
  }
  if (!stop && !lcm_util::StopRequested()) {
    router.Flush();
    handle(assembler.Flush());
  }
  bar.Done(detail());

  st.decode_errors = router.total_decode_errors();
  st.late_dropped = assembler.stats().late_dropped;
  st.warnings = reader.IncompleteLogs();
  st.wall_s = Since(t0);
  return st;
}

}  // namespace vtrack::viewer
