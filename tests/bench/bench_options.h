// Command-line options of the benchmark programs that are not Google Benchmark ones
// (e2e_latency, tracker_soak).
#pragma once

#include <boost/program_options.hpp>

#include <exception>
#include <iostream>
#include <optional>

namespace vtrack::bench {

// Parses argv into the variables of desc (which has "help"). Returns nothing to go on, or the
// exit status: 0 after printing the options for --help, 2 after saying what was wrong with them.
inline std::optional<int> ParseOptions(const char* program,
                                       const boost::program_options::options_description& desc,
                                       int argc, char** argv) {
  namespace po = boost::program_options;
  po::variables_map vm;
  try {
    po::store(po::parse_command_line(argc, argv, desc), vm);
    if (vm.count("help")) {
      std::cout << desc << "\n";
      return 0;
    }
    po::notify(vm);
  } catch (const std::exception& e) {
    std::cerr << program << ": " << e.what() << "\n" << desc << "\n";
    return 2;
  }
  return std::nullopt;
}

}  // namespace vtrack::bench
