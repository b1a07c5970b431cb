#include "lcmtypes/util/ladar_slices.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "base/angle.h"

namespace vtrack::lcm_util {
namespace {

// Bytes per return in a slice: x, y, z, intensity (float), dt_us (int32), ring (int16).
constexpr std::int64_t kBytesPerReturn = 4 * 4 + 4 + 2;
// [rad] A slice's arc may exceed one turn by this much (rounding of begin + width).
constexpr double kArcSlack = 1e-9;
// Most sweeps pending at once (of all sensors): beyond it the oldest is handed on, so that a
// stream of slices that never complete cannot grow the memory.
constexpr std::size_t kMaxPending = 16;
// [us] A slice this much older than the newest sweep handed on starts a new stream (a restarted
// driver or a looped log), not a late slice.
constexpr std::int64_t kRestartUs = 1'000'000;

// begin in [-pi, pi).
double WrapBegin(double a) {
  const double w = WrapToPi(a);
  return w >= kPi ? w - 2.0 * kPi : w;
}

// The columns of a sweep: runs of consecutive returns with the same dt_us.
struct Column {
  std::size_t first = 0, end = 0;  // [first, end) in the scan's arrays
  double azimuth = std::nan("");   // [rad] of the column's first finite return
};

std::vector<Column> Columns(const ladar_scan_t& scan) {
  std::vector<Column> cols;
  const std::size_t n = scan.x.size();
  for (std::size_t i = 0; i < n;) {
    Column c;
    c.first = i;
    while (i < n && scan.dt_us[i] == scan.dt_us[c.first]) {
      if (std::isnan(c.azimuth) && std::isfinite(scan.x[i]) && std::isfinite(scan.y[i])) {
        c.azimuth = std::atan2(static_cast<double>(scan.y[i]), static_cast<double>(scan.x[i]));
      }
      ++i;
    }
    c.end = i;
    cols.push_back(c);
  }
  return cols;
}

// Where the arcs start and the direction the sensor turned (+1 counter-clockwise, -1 clockwise:
// the sign of the summed steps from column to column). The start lies half a column step before
// the first column, so that no column sits on the seam (the layers of one column differ in
// azimuth by float rounding).
void StartAndDirection(const std::vector<Column>& cols, double* start, double* direction) {
  double first = 0.0, total = 0.0, first_step = 0.0, prev = std::nan("");
  for (const Column& c : cols) {
    if (std::isnan(c.azimuth)) continue;
    if (std::isnan(prev)) {
      first = c.azimuth;
    } else {
      const double step = AngleDiff(c.azimuth, prev);
      if (first_step == 0.0) first_step = std::abs(step);
      total += step;
    }
    prev = c.azimuth;
  }
  *direction = total < 0.0 ? -1.0 : 1.0;
  *start = first - *direction * 0.5 * first_step;
}

// The arc (0 .. count-1) of every column; a column without a finite return goes with the one
// before it (arc 0 at the start).
std::vector<int> ArcOfColumns(const std::vector<Column>& cols, int count) {
  double start = 0.0, direction = 1.0;
  StartAndDirection(cols, &start, &direction);
  const double width = 2.0 * kPi / count;
  std::vector<int> arc(cols.size(), 0);
  int last = 0;
  for (std::size_t j = 0; j < cols.size(); ++j) {
    if (!std::isnan(cols[j].azimuth)) {
      double phi = direction * (cols[j].azimuth - start);  // turned since the start
      phi = std::fmod(phi, 2.0 * kPi);
      if (phi < 0.0) phi += 2.0 * kPi;
      last = std::min(count - 1, static_cast<int>(phi / width));
    }
    arc[j] = last;
  }
  return arc;
}

void CheckArrays(const ladar_scan_t& scan) {
  const std::size_t n = scan.x.size();
  if (scan.y.size() != n || scan.z.size() != n || scan.intensity.size() != n ||
      scan.dt_us.size() != n || scan.ring.size() != n ||
      static_cast<std::size_t>(scan.npoints) != n) {
    throw std::invalid_argument("ladar_scan_t " + std::to_string(scan.seq) +
                                ": parallel arrays of different lengths (npoints " +
                                std::to_string(scan.npoints) + ")");
  }
}

ladar_slice_t SliceHeader(const ladar_scan_t& scan) {
  ladar_slice_t s{};
  s.utime = scan.utime;
  s.seq = scan.seq;
  s.sensor_id = scan.sensor_id;
  std::copy(scan.sensor_pos, scan.sensor_pos + 3, s.sensor_pos);
  std::copy(scan.sensor_orientation, scan.sensor_orientation + 4, s.sensor_orientation);
  s.sweep_duration_us = scan.sweep_duration_us;
  s.max_range = scan.max_range;
  s.num_rings = scan.num_rings;
  s.npoints = 0;
  return s;
}

ladar_scan_t ScanHeader(const ladar_slice_t& s) {
  ladar_scan_t scan{};
  scan.utime = s.utime;
  scan.seq = s.seq;
  scan.sensor_id = s.sensor_id;
  std::copy(s.sensor_pos, s.sensor_pos + 3, scan.sensor_pos);
  std::copy(s.sensor_orientation, s.sensor_orientation + 4, scan.sensor_orientation);
  scan.sweep_duration_us = s.sweep_duration_us;
  scan.max_range = s.max_range;
  scan.num_rings = s.num_rings;
  scan.npoints = 0;
  return scan;
}

bool SameSweepHeader(const ladar_slice_t& a, const ladar_slice_t& b) {
  return a.utime == b.utime && a.slice_count == b.slice_count &&
         std::equal(a.sensor_pos, a.sensor_pos + 3, b.sensor_pos) &&
         std::equal(a.sensor_orientation, a.sensor_orientation + 4, b.sensor_orientation) &&
         a.sweep_duration_us == b.sweep_duration_us && a.max_range == b.max_range &&
         a.num_rings == b.num_rings;
}

template <class T>
void Append(const std::vector<T>& from, std::vector<T>* to) {
  to->insert(to->end(), from.begin(), from.end());
}

}  // namespace

std::int64_t SliceEncodedSize(const ladar_scan_t& scan, std::int64_t n) {
  return SliceHeader(scan).getEncodedSize() + n * kBytesPerReturn;
}

int AutoSliceCount(const ladar_scan_t& scan, std::int64_t max_bytes) {
  CheckArrays(scan);
  const std::int64_t header = SliceEncodedSize(scan, 0);
  const std::int64_t per_slice = (max_bytes - header) / kBytesPerReturn;  // returns that fit
  if (per_slice < 1) throw std::invalid_argument("a slice header alone exceeds the size limit");
  const std::vector<Column> cols = Columns(scan);
  const std::int64_t n = static_cast<std::int64_t>(scan.x.size());
  // Equal arcs hold unequal numbers of returns: start from the even split and add slices until
  // the fullest arc fits.
  for (int count = static_cast<int>(std::max<std::int64_t>(1, (n + per_slice - 1) / per_slice));
       count <= kMaxSlicesPerSweep; ++count) {
    const std::vector<int> arc = ArcOfColumns(cols, count);
    std::vector<std::int64_t> in_arc(static_cast<std::size_t>(count), 0);
    for (std::size_t j = 0; j < cols.size(); ++j) {
      in_arc[static_cast<std::size_t>(arc[j])] += static_cast<std::int64_t>(cols[j].end - cols[j].first);
    }
    if (*std::max_element(in_arc.begin(), in_arc.end()) <= per_slice) return count;
  }
  throw std::invalid_argument("sweep " + std::to_string(scan.seq) + " of " + std::to_string(n) +
                              " returns does not fit in " + std::to_string(kMaxSlicesPerSweep) +
                              " slices of " + std::to_string(max_bytes) + " bytes");
}

std::vector<ladar_slice_t> SliceSweep(const ladar_scan_t& scan, int count) {
  CheckArrays(scan);
  if (count == 0) count = AutoSliceCount(scan);
  if (count < 1 || count > kMaxSlicesPerSweep) {
    throw std::invalid_argument("slice count " + std::to_string(count) + " must be in [1, " +
                                std::to_string(kMaxSlicesPerSweep) + "] (0: automatic)");
  }
  const std::vector<Column> cols = Columns(scan);
  const std::vector<int> arc = ArcOfColumns(cols, count);
  double start = 0.0, direction = 1.0;
  StartAndDirection(cols, &start, &direction);
  const double width = 2.0 * kPi / count;
  std::vector<ladar_slice_t> slices(static_cast<std::size_t>(count), SliceHeader(scan));
  for (int k = 0; k < count; ++k) {
    ladar_slice_t& s = slices[static_cast<std::size_t>(k)];
    s.slice_index = k;
    s.slice_count = count;
    // Arc k runs from start + k width onwards in the direction of the turn.
    s.azimuth_begin = WrapBegin(direction > 0.0 ? start + k * width : start - (k + 1) * width);
    s.azimuth_end = s.azimuth_begin + width;
  }
  for (std::size_t j = 0; j < cols.size(); ++j) {
    ladar_slice_t& s = slices[static_cast<std::size_t>(arc[j])];
    for (std::size_t i = cols[j].first; i < cols[j].end; ++i) {
      s.x.push_back(scan.x[i]);
      s.y.push_back(scan.y[i]);
      s.z.push_back(scan.z[i]);
      s.intensity.push_back(scan.intensity[i]);
      s.dt_us.push_back(scan.dt_us[i]);
      s.ring.push_back(scan.ring[i]);
    }
  }
  for (ladar_slice_t& s : slices) s.npoints = static_cast<std::int32_t>(s.x.size());
  return slices;
}

std::optional<int> ParseSlicesOption(const std::string& text) {
  if (text == "auto") return kSlicesAuto;
  if (text.empty() || text.size() > 5 ||
      !std::all_of(text.begin(), text.end(), [](char c) { return c >= '0' && c <= '9'; })) {
    return std::nullopt;
  }
  const int n = std::stoi(text);
  if (n > kMaxSlicesPerSweep) return std::nullopt;
  return n;
}

int SlicesFor(int option, const ladar_scan_t& scan) {
  if (option != kSlicesAuto) return option;
  return scan.num_rings > 1 ? AutoSliceCount(scan) : 0;
}

double AssembledSweep::MissingDeg() const {
  double w = 0.0;
  for (const AzimuthArc& a : missing) w += a.width();
  return RadToDeg(w);
}

std::vector<AzimuthArc> UncoveredArcs(std::vector<AzimuthArc> covered) {
  if (covered.empty()) return {AzimuthArc{-kPi, kPi}};
  // Unrolled onto [origin, origin + 2 pi) from the first arc's begin, in order of begin.
  const double origin = covered.front().begin;
  for (AzimuthArc& a : covered) {
    double shift = std::fmod(a.begin - origin, 2.0 * kPi);
    if (shift < 0.0) shift += 2.0 * kPi;
    const double w = a.width();
    a.begin = origin + shift;
    a.end = a.begin + w;
  }
  std::sort(covered.begin(), covered.end(),
            [](const AzimuthArc& a, const AzimuthArc& b) { return a.begin < b.begin; });
  std::vector<AzimuthArc> gaps;
  double reached = origin;  // everything in [origin, reached) is covered
  for (const AzimuthArc& a : covered) {
    if (a.begin > reached + 1e-9) gaps.push_back({reached, a.begin});
    reached = std::max(reached, a.end);
  }
  if (reached + 1e-9 < origin + 2.0 * kPi) gaps.push_back({reached, origin + 2.0 * kPi});
  for (AzimuthArc& g : gaps) {
    const double w = g.width();
    g.begin = WrapBegin(g.begin);
    g.end = g.begin + w;
  }
  return gaps;
}

SweepAssembler::SweepAssembler(Options options) : options_(options) {
  if (options_.reorder_window_us < 0 || options_.timeout_us < 0) {
    throw std::invalid_argument("SweepAssembler: reorder_window_us " +
                                std::to_string(options_.reorder_window_us) + " and timeout_us " +
                                std::to_string(options_.timeout_us) + " must be >= 0");
  }
}

std::string SweepAssembler::Check(const ladar_slice_t& s) const {
  if (s.slice_count < 1 || s.slice_count > kMaxSlicesPerSweep || s.slice_index < 0 ||
      s.slice_index >= s.slice_count) {
    return "slice_bad_index";
  }
  if (!std::isfinite(s.azimuth_begin) || !std::isfinite(s.azimuth_end) ||
      s.azimuth_begin < -kPi || s.azimuth_begin > kPi || !(s.azimuth_end > s.azimuth_begin) ||
      s.azimuth_end - s.azimuth_begin > 2.0 * kPi + kArcSlack) {
    return "slice_bad_arc";
  }
  const auto it = pending_.find(Key{s.sensor_id, s.seq});
  if (it != pending_.end()) {
    const Pending& p = it->second;
    const auto any = std::find_if(p.slices.begin(), p.slices.end(),
                                  [](const ladar_slice_t& o) { return o.npoints >= 0; });
    if (!SameSweepHeader(*any, s)) return "slice_inconsistent";
    if (p.slices[static_cast<std::size_t>(s.slice_index)].npoints >= 0) return "slice_duplicate";
  }
  return "";
}

void SweepAssembler::Add(ladar_slice_t&& slice, std::vector<AssembledSweep>* out) {
  const auto handed = handed_on_utime_.find(slice.sensor_id);
  if (handed != handed_on_utime_.end() && slice.utime <= handed->second) {
    if (handed->second - slice.utime <= kRestartUs) {
      ++refused_["slice_late"];
      return;
    }
    // A new stream: what is pending of the old one goes first.
    CloseSensorBefore(slice.sensor_id, INT64_MAX, out);
    handed_on_utime_.erase(slice.sensor_id);
  }
  const std::string why = Check(slice);
  if (!why.empty()) {
    ++refused_[why];
    return;
  }
  // Sweeps of this sensor that ended more than the window before this one started are done.
  CloseSensorBefore(slice.sensor_id, slice.utime - options_.reorder_window_us, out);
  const Key key{slice.sensor_id, slice.seq};
  if (pending_.size() >= kMaxPending && pending_.count(key) == 0) HandOnOldest(out);
  Pending& p = pending_[key];
  if (p.slices.empty()) {
    ladar_slice_t none{};
    none.npoints = -1;
    p.slices.assign(static_cast<std::size_t>(slice.slice_count), none);
  }
  const std::size_t k = static_cast<std::size_t>(slice.slice_index);
  p.slices[k] = std::move(slice);
  ++p.received;
  ++slices_accepted_;
  if (p.received == static_cast<std::int32_t>(p.slices.size())) {
    const std::int64_t utime = p.slices[k].utime;
    CloseSensorBefore(key.first, utime, out);  // older sweeps first, incomplete
    HandOn(pending_.find(key), out);
  }
}

void SweepAssembler::CloseSensorBefore(const std::string& sensor, std::int64_t end_before,
                                       std::vector<AssembledSweep>* out) {
  // Collected first, then handed on in time order (the map is ordered by seq, not by time).
  std::vector<std::pair<std::int64_t, Key>> due;
  for (auto& [key, p] : pending_) {
    if (key.first != sensor) continue;
    const auto any = std::find_if(p.slices.begin(), p.slices.end(),
                                  [](const ladar_slice_t& o) { return o.npoints >= 0; });
    const std::int64_t end = any->utime + any->sweep_duration_us;
    if (end < end_before) due.emplace_back(any->utime, key);
  }
  std::sort(due.begin(), due.end());
  for (const auto& d : due) HandOn(pending_.find(d.second), out);
}

void SweepAssembler::HandOnOldest(std::vector<AssembledSweep>* out) {
  auto oldest = pending_.end();
  std::int64_t oldest_utime = INT64_MAX;
  for (auto it = pending_.begin(); it != pending_.end(); ++it) {
    for (const ladar_slice_t& s : it->second.slices) {
      if (s.npoints >= 0 && s.utime < oldest_utime) {
        oldest_utime = s.utime;
        oldest = it;
      }
    }
  }
  if (oldest != pending_.end()) HandOn(oldest, out);
}

void SweepAssembler::Expire(std::int64_t now_utime, std::vector<AssembledSweep>* out) {
  std::vector<std::string> sensors;
  for (const auto& [key, p] : pending_) {
    if (sensors.empty() || sensors.back() != key.first) sensors.push_back(key.first);
  }
  for (const std::string& s : sensors) CloseSensorBefore(s, now_utime - options_.timeout_us, out);
}

void SweepAssembler::Flush(std::vector<AssembledSweep>* out) {
  std::vector<std::string> sensors;
  for (const auto& [key, p] : pending_) {
    if (sensors.empty() || sensors.back() != key.first) sensors.push_back(key.first);
  }
  for (const std::string& s : sensors) CloseSensorBefore(s, INT64_MAX, out);
}

void SweepAssembler::HandOn(std::map<Key, Pending>::iterator it, std::vector<AssembledSweep>* out) {
  Pending& p = it->second;
  AssembledSweep a;
  a.slice_count = static_cast<std::int32_t>(p.slices.size());
  a.slices_received = p.received;
  std::vector<AzimuthArc> covered;
  // Each array allocated once at its final size: grown slice by slice it was copied and
  // reallocated a dozen times, and fresh pages fault on first touch.
  std::size_t total = 0;
  for (const ladar_slice_t& s : p.slices) total += s.npoints >= 0 ? s.x.size() : 0;
  bool first = true;
  for (ladar_slice_t& s : p.slices) {
    if (s.npoints < 0) continue;
    if (first) {
      a.scan = ScanHeader(s);
      a.scan.x.reserve(total);
      a.scan.y.reserve(total);
      a.scan.z.reserve(total);
      a.scan.intensity.reserve(total);
      a.scan.dt_us.reserve(total);
      a.scan.ring.reserve(total);
    }
    first = false;
    covered.push_back({s.azimuth_begin, s.azimuth_end});
    Append(s.x, &a.scan.x);
    Append(s.y, &a.scan.y);
    Append(s.z, &a.scan.z);
    Append(s.intensity, &a.scan.intensity);
    Append(s.dt_us, &a.scan.dt_us);
    Append(s.ring, &a.scan.ring);
  }
  a.scan.npoints = static_cast<std::int32_t>(a.scan.x.size());
  if (a.partial()) {
    a.missing = UncoveredArcs(std::move(covered));
    slices_lost_ += a.slice_count - a.slices_received;
    missing_deg_ += a.MissingDeg();
    ++sweeps_partial_;
  } else {
    ++sweeps_whole_;
  }
  const auto [newest, inserted] = handed_on_utime_.try_emplace(it->first.first, a.scan.utime);
  if (!inserted) newest->second = std::max(newest->second, a.scan.utime);
  pending_.erase(it);
  out->push_back(std::move(a));
}

}  // namespace vtrack::lcm_util
