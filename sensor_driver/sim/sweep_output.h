// How the drivers (vtrack-ladar-driver, vtrack-sim-log) put a sweep on the bus: whole, as one
// ladar_scan_t on the scan channel, or as azimuth slices (ladar_slice_t, one UDP datagram each)
// on the slice channel (lcmtypes/util/ladar_slices.h). Default (--slices auto): slices for 3-D
// sweeps (megabytes, which LCM would send as dozens of fragments, all lost with any one), whole
// for single-plane ones (they fit one datagram).
#pragma once

#include <boost/program_options.hpp>

#include <chrono>
#include <string>
#include <thread>
#include <vector>

#include "lcmtypes/util/ladar_slices.h"
#include "vtrack/ladar_scan_t.hpp"

namespace vtrack::sim {

struct SweepOutput {
  std::string scan_channel = "LADAR_SCAN";
  std::string slice_channel = "LADAR_SLICE";
  int slices = lcm_util::kSlicesAuto;  // lcm_util::ParseSlicesOption
  int slice_gap_us = lcm_util::kSliceGapUs;  // [us] live only: wall time between two slices
};

// --scan-channel, --slice-channel, --slices (and, live, --slice-gap-us).
void AddSweepOutputOptions(boost::program_options::options_description* desc, bool live);
// Throws boost::program_options::error for a --slices that is not auto, 0 or a count.
SweepOutput ReadSweepOutputOptions(const boost::program_options::variables_map& vm);

// Sends scan as output says through send(channel, msg) (msg a ladar_scan_t or a ladar_slice_t);
// returns the number of slices sent (0: sent whole). paced: output.slice_gap_us of wall time
// between two slices (live; a log writer does not wait).
template <class Send>
int SendSweep(const SweepOutput& output, const ladar_scan_t& scan, Send&& send, bool paced = false) {
  const int n = lcm_util::SlicesFor(output.slices, scan);
  if (n == 0) {
    send(output.scan_channel, scan);
    return 0;
  }
  const std::vector<ladar_slice_t> slices = lcm_util::SliceSweep(scan, n);
  for (std::size_t k = 0; k < slices.size(); ++k) {
    if (paced && k > 0 && output.slice_gap_us > 0) {
      std::this_thread::sleep_for(std::chrono::microseconds(output.slice_gap_us));
    }
    send(output.slice_channel, slices[k]);
  }
  return n;
}

}  // namespace vtrack::sim
