// The --help handling that the vtrack tools share (boost::program_options). Header only, so that
// tools linking nothing else of vtrack_msgs use it too.
#pragma once

#include <boost/program_options.hpp>

#include <iostream>
#include <string>
#include <typeinfo>

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

// Throws boost::program_options::error if a channel option ("channel" or "...-channel", a
// string) is empty: LCM would publish on, or subscribe to, a channel no one else names.
inline void RefuseEmptyChannels(const boost::program_options::variables_map& vm) {
  for (const auto& [key, value] : vm) {
    const bool channel = key == "channel" ||
                         (key.size() > 8 && key.compare(key.size() - 8, 8, "-channel") == 0);
    if (!channel || value.empty() || value.value().type() != typeid(std::string)) continue;
    if (value.as<std::string>().empty()) {
      throw boost::program_options::error("--" + key + " must not be empty");
    }
  }
}

// Stores parsed into *vm. If --help is among the options, prints usage (if not empty, followed by
// a blank line) and help to stdout and returns false: the process should exit 0. Otherwise runs
// the notifiers and returns true. Throws boost::program_options::error for a bad command line,
// including an argument that is not an option (RefuseStrayArguments) and an empty channel
// (RefuseEmptyChannels).
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
  RefuseEmptyChannels(*vm);
  return true;
}

}  // namespace vtrack::lcm_util
