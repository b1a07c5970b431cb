// How the drivers (vtrack-ladar-driver, vtrack-sim-log) put a sweep on the bus: whole, as one
// ladar_scan_t on the scan channel, or as azimuth slices (ladar_slice_t, one UDP datagram each)
// on the slice channel (lcmtypes/util/ladar_slices.h). Default (--slices auto): slices for 3-D
// sweeps (megabytes, which LCM would send as dozens of fragments, all lost with any one), whole
// for single-plane ones (they fit one datagram).
#pragma once

#include <boost/program_options.hpp>

#include <string>

#include "lcmtypes/util/ladar_slices.h"
#include "vtrack/ladar_scan_t.hpp"

namespace vtrack::sim {

struct SweepOutput {
  std::string scan_channel = "LADAR_SCAN";
  std::string slice_channel = "LADAR_SLICE";
  int slices = lcm_util::kSlicesAuto;  // lcm_util::ParseSlicesOption
};

// --scan-channel, --slice-channel, --slices.
void AddSweepOutputOptions(boost::program_options::options_description* desc);
// Throws boost::program_options::error for a --slices that is not auto, 0 or a count.
SweepOutput ReadSweepOutputOptions(const boost::program_options::variables_map& vm);

// Sends scan as output says through send(channel, msg) (msg a ladar_scan_t or a ladar_slice_t);
// returns the number of slices sent (0: sent whole).
template <class Send>
int SendSweep(const SweepOutput& output, const ladar_scan_t& scan, Send&& send) {
  const int n = lcm_util::SlicesFor(output.slices, scan);
  if (n == 0) {
    send(output.scan_channel, scan);
    return 0;
  }
  for (const ladar_slice_t& s : lcm_util::SliceSweep(scan, n)) send(output.slice_channel, s);
  return n;
}

}  // namespace vtrack::sim
