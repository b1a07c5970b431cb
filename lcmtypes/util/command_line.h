// The --help handling that the vtrack tools share (boost::program_options). Header only, so that
// tools linking nothing else of vtrack_msgs use it too.
#pragma once

#include <boost/program_options.hpp>

#include <iostream>
#include <string>

namespace vtrack::lcm_util {

// Stores parsed into *vm. If --help is among the options, prints usage (if not empty, followed by
// a blank line) and help to stdout and returns false: the process should exit 0. Otherwise runs
// the notifiers and returns true. Throws boost::program_options::error for a bad command line.
inline bool StoreCommandLine(const boost::program_options::parsed_options& parsed,
                             const boost::program_options::options_description& help,
                             boost::program_options::variables_map* vm,
                             const std::string& usage = "") {
  boost::program_options::store(parsed, *vm);
  if (vm->count("help")) {
    if (!usage.empty()) std::cout << usage << "\n\n";
    std::cout << help << "\n";
    return false;
  }
  boost::program_options::notify(*vm);
  return true;
}

}  // namespace vtrack::lcm_util
