#include "sensor_driver/driver/realtime.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <thread>

#include "lcmtypes/util/process.h"

namespace vtrack::sim {
namespace {

using lcm_util::WallUtime;

std::int64_t FloorDiv(std::int64_t a, std::int64_t b) {
  const std::int64_t q = a / b;
  return (a % b != 0 && ((a < 0) != (b < 0))) ? q - 1 : q;
}

// Sleeps until the wall clock reaches utime; false if a stop was requested meanwhile.
bool SleepUntil(std::int64_t utime) {
  while (!lcm_util::StopRequested()) {
    const std::int64_t left = utime - WallUtime();
    if (left <= 0) return true;
    std::this_thread::sleep_for(std::chrono::microseconds(std::min<std::int64_t>(left, 100'000)));
  }
  return false;
}

}  // namespace

RealtimeStats RunRealtime(Timeline& timeline, const RealtimeOptions& o) {
  if (o.lap_us <= 0) throw std::invalid_argument("lap length must be > 0 us");
  if (o.laps < 0) throw std::invalid_argument("--laps = " + std::to_string(o.laps) + ": must be >= 0");
  if (o.stop_after_s < 0) throw std::invalid_argument("--stop-after must be >= 0");
  if (!(o.rate > 0.0) || !std::isfinite(o.rate)) {
    throw std::invalid_argument("--rate = " + std::to_string(o.rate) + ": must be > 0");
  }
  if (o.rate != 1.0 && !o.start_utime) {
    throw std::invalid_argument("--rate other than 1 needs --start-utime (the utime at which data "
                                "time and wall time coincide; give both processes the same)");
  }
  RealtimeStats stats;
  const int n = timeline.Count();
  if (n == 0) return stats;
  const std::int64_t U = o.start_utime.value_or(0);
  // Data time runs at `rate` data seconds per wall second from U, where the two coincide. Every
  // schedule decision below is in data time; only sleeping converts back to the wall clock.
  const auto data_now = [&] {
    const std::int64_t wall = WallUtime();
    return o.rate == 1.0 ? wall : U + static_cast<std::int64_t>(std::llround((wall - U) * o.rate));
  };
  const auto wall_at = [&](std::int64_t data) {
    return o.rate == 1.0 ? data : U + static_cast<std::int64_t>(std::llround((data - U) / o.rate));
  };
  const std::int64_t start_data = data_now();
  const std::int64_t deadline =
      o.stop_after_s > 0
          ? start_data + static_cast<std::int64_t>(o.stop_after_s * 1e6 * o.rate)
          : 0;
  const std::int64_t late_us = static_cast<std::int64_t>(o.late_limit_s * 1e6);

  std::int64_t first_lap;
  if (o.start_utime) {
    first_lap = std::max<std::int64_t>(0, FloorDiv(start_data - U, o.lap_us));
    if (o.laps > 0 && first_lap >= o.laps) {
      throw std::runtime_error("the " + std::to_string(o.laps) + " lap(s) from --start-utime " +
                               std::to_string(U) + " ended " +
                               std::to_string((start_data - U - o.laps * o.lap_us) / 1000000) +
                               " s ago");
    }
    if (start_data < U) {
      std::fprintf(stderr, "%s: waiting %.1f s for the run to start at utime %lld\n",
                   o.name.c_str(), (U - start_data) * 1e-6 / o.rate, static_cast<long long>(U));
    }
  } else {
    first_lap = FloorDiv(start_data - U, o.lap_us);
  }
  const std::int64_t end_lap = o.laps > 0 ? (o.start_utime ? o.laps : first_lap + o.laps) : INT64_MAX;
  std::fprintf(stderr, "%s: laps of %.3f s%s; lap %lld started at utime %lld (t = %.2f s now)\n",
               o.name.c_str(), o.lap_us * 1e-6,
               o.rate == 1.0 ? "" : (" at rate " + std::to_string(o.rate)).c_str(),
               static_cast<long long>(first_lap),
               static_cast<long long>(U + first_lap * o.lap_us),
               std::max<std::int64_t>(0, start_data - U - first_lap * o.lap_us) * 1e-6);

  const auto interval_us = static_cast<std::int64_t>(o.progress_interval_s * 1e6 * o.rate);
  std::int64_t next_progress = start_data + interval_us;
  for (std::int64_t lap = first_lap; lap < end_lap; ++lap) {
    const std::int64_t lap_start = U + lap * o.lap_us;
    int i = 0;
    while (i < n) {
      if (lcm_util::StopRequested()) return stats;
      std::int64_t now = data_now();
      if (deadline && now >= deadline) return stats;
      // Joining mid-lap, or fallen behind: go to the first item that is not overdue.
      if (now > lap_start + timeline.PublishOffsetUs(i) + late_us) {
        const int from = i;
        while (i < n && lap_start + timeline.PublishOffsetUs(i) < now) ++i;
        if (lap > first_lap || from > 0) stats.skipped += i - from;
        if (i >= n) break;
      }
      timeline.Prepare(i, lap_start, lap);
      const std::int64_t due = lap_start + timeline.PublishOffsetUs(i);
      if (deadline && due >= deadline) return stats;
      if (!SleepUntil(wall_at(due))) return stats;
      timeline.Publish();
      ++stats.published;
      ++i;
      now = data_now();
      if (o.progress_interval_s > 0 && now >= next_progress) {
        std::fprintf(stderr, "%s: lap %lld, t = %.1f s: %lld %s published, %lld skipped\n",
                     o.name.c_str(), static_cast<long long>(lap), (now - lap_start) * 1e-6,
                     static_cast<long long>(stats.published), o.what.c_str(),
                     static_cast<long long>(stats.skipped));
        next_progress = now + interval_us;
      }
    }
  }
  return stats;
}

}  // namespace vtrack::sim
