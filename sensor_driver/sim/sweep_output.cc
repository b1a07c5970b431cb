#include "sensor_driver/sim/sweep_output.h"

namespace vtrack::sim {

namespace po = boost::program_options;

void AddSweepOutputOptions(po::options_description* desc, bool live) {
  desc->add_options()
      ("scan-channel", po::value<std::string>()->default_value("LADAR_SCAN"),
       "channel of whole sweeps (ladar_scan_t)")
      ("slice-channel", po::value<std::string>()->default_value("LADAR_SLICE"),
       "channel of sweeps sent as slices (ladar_slice_t)")
      ("slices", po::value<std::string>()->default_value("auto"),
       "auto | N | 0: send each sweep as azimuth slices of one UDP datagram each (auto: as many "
       "as that takes, for 3-D sensors; single-plane sweeps whole), as N slices, or whole (0)");
  if (live) {
    desc->add_options()
        ("slice-gap-us", po::value<int>()->default_value(lcm_util::kSliceGapUs),
         "[us] wall time between two slices of a sweep, [0, 10000] (lcm-logger drops messages "
         "behind a burst of more than 30)");
  }
}

SweepOutput ReadSweepOutputOptions(const po::variables_map& vm) {
  SweepOutput o;
  o.scan_channel = vm["scan-channel"].as<std::string>();
  o.slice_channel = vm["slice-channel"].as<std::string>();
  const std::string text = vm["slices"].as<std::string>();
  const std::optional<int> n = lcm_util::ParseSlicesOption(text);
  if (!n) {
    throw po::error("--slices '" + text + "' must be auto, 0 or a count in [1, " +
                    std::to_string(lcm_util::kMaxSlicesPerSweep) + "]");
  }
  o.slices = *n;
  if (vm.count("slice-gap-us")) {
    o.slice_gap_us = vm["slice-gap-us"].as<int>();
    if (o.slice_gap_us < 0 || o.slice_gap_us > 10000) {
      throw po::error("--slice-gap-us " + std::to_string(o.slice_gap_us) + " must be in [0, 10000]");
    }
  }
  return o;
}

}  // namespace vtrack::sim
