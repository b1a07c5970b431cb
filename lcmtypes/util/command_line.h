// The --help handling that the vtrack tools share (boost::program_options). Header only, so that
// tools linking nothing else of vtrack_msgs use it too.
#pragma once

#include <boost/program_options.hpp>
#include <unistd.h>

#include <filesystem>
#include <iostream>
#include <string>
#include <typeinfo>
#include <utility>
#include <vector>

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

// A file named on the command line: the option that names it ("--output", or "" for a
// positional argument) and its path.
struct PathArgument {
  std::string option;
  std::string path;
};

// True if a and b name the same file: the same existing file (a link, a relative and an absolute
// path, a hard link), or one not there yet named by the same normalised absolute path.
inline bool SameFile(const std::string& a, const std::string& b) {
  std::error_code ec;
  if (std::filesystem::equivalent(a, b, ec) && !ec) return true;
  const auto normal = [](const std::string& p) {
    std::error_code e;
    const std::filesystem::path abs = std::filesystem::absolute(p, e);
    const std::filesystem::path canonical = std::filesystem::weakly_canonical(abs, e);
    // A look-up refused (a folder without search permission): the path as written, normalised.
    return (e || canonical.empty() ? abs : canonical).lexically_normal();
  };
  return normal(a) == normal(b);
}

// "" if path can be written: an existing file that is writable, or a new one in a writable
// folder (through a symbolic link, the file it names); else why not. Nothing is created.
inline std::string WhyNotWritable(const std::string& path) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::path target = fs::weakly_canonical(fs::absolute(path, ec), ec);
  const fs::path p = ec || target.empty() ? fs::path(path) : target;
  const fs::file_status st = fs::status(p, ec);
  if (fs::is_directory(st)) return "is a directory";
  if (fs::exists(st)) return ::access(p.c_str(), W_OK) == 0 ? "" : "is not writable";
  const fs::path folder = p.has_parent_path() ? p.parent_path() : fs::path(".");
  if (!fs::is_directory(folder, ec)) return "its folder " + folder.string() + " does not exist";
  return ::access(folder.c_str(), W_OK) == 0 ? "" : "its folder " + folder.string() + " is not writable";
}

// Throws boost::program_options::error if an output would overwrite an input or another output
// (each written over the other: the input lost, or one output cut short), naming both options.
// Empty paths are not files, and "-" (standard output) or a device such as /dev/null is never one.
inline void RefuseOverwritingInputs(const std::vector<PathArgument>& inputs,
                                    const std::vector<PathArgument>& outputs) {
  const auto name = [](const PathArgument& a) {
    return (a.option.empty() ? std::string() : a.option + " ") + "'" + a.path + "'";
  };
  const auto is_file = [](const std::string& p) {
    std::error_code ec;
    const auto st = std::filesystem::status(p, ec);
    return !p.empty() && p != "-" && (!std::filesystem::exists(st) || std::filesystem::is_regular_file(st));
  };
  for (std::size_t o = 0; o < outputs.size(); ++o) {
    if (!is_file(outputs[o].path)) continue;
    for (const PathArgument& in : inputs) {
      if (!in.path.empty() && SameFile(outputs[o].path, in.path)) {
        throw boost::program_options::error(name(outputs[o]) + " is also the input " + name(in) +
                                            ": writing it would destroy the input");
      }
    }
    for (std::size_t k = 0; k < o; ++k) {
      if (is_file(outputs[k].path) && SameFile(outputs[o].path, outputs[k].path)) {
        throw boost::program_options::error(name(outputs[o]) + " and " + name(outputs[k]) +
                                            " are the same file: give each output its own");
      }
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
