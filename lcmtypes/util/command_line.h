// The --help handling that the vtrack tools share (boost::program_options). Header only, so that
// tools linking nothing else of vtrack_msgs use it too.
#pragma once

#include <boost/program_options.hpp>

#include <iostream>
#include <string>

namespace vtrack::lcm_util {

// Throws boost::program_options::error naming the first argument that is neither an option nor
// one of the tool's positional arguments. boost::program_options drops such arguments without a
// word, and a tool that ignored a mistyped "vtrack-monitor run.lcm" would go live instead.
inline void RefuseStrayArguments(const boost::program_options::parsed_options& parsed) {
  for (const auto& o : parsed.options) {
    if (!o.string_key.empty()) continue;
    const std::string arg = !o.original_tokens.empty() ? o.original_tokens.front()
                            : !o.value.empty()        ? o.value.front()
                                                      : std::string();
    throw boost::program_options::error("unexpected argument '" + arg + "'");
  }
}

// Throws boost::program_options::error unless value is non-empty (a channel name).
inline void RefuseEmpty(const boost::program_options::variables_map& vm, const char* key) {
  if (vm.count(key) && vm[key].as<std::string>().empty()) {
    throw boost::program_options::error(std::string("--") + key + " must not be empty");
  }
}

// Stores parsed into *vm. If --help is among the options, prints usage (if not empty, followed by
// a blank line) and help to stdout and returns false: the process should exit 0. Otherwise runs
// the notifiers and returns true. Throws boost::program_options::error for a bad command line,
// including an argument that is not an option (RefuseStrayArguments).
inline bool StoreCommandLine(const boost::program_options::parsed_options& parsed,
                             const boost::program_options::options_description& help,
                             boost::program_options::variables_map* vm,
                             const std::string& usage = "") {
  boost::program_options::store(parsed, *vm);
  if (!vm->count("help")) RefuseStrayArguments(parsed);
  if (vm->count("help")) {
    if (!usage.empty()) std::cout << usage << "\n\n";
    std::cout << help << "\n";
    return false;
  }
  boost::program_options::notify(*vm);
  return true;
}

}  // namespace vtrack::lcm_util
