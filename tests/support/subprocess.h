// A child process for tests that drive the real executables (lcm-logger, vtrack-* tools).
// The destructor ends the child by its PID (SIGTERM, then SIGKILL) and reaps it: no test leaves
// a process behind.
#pragma once

#include <sys/types.h>

#include <chrono>
#include <optional>
#include <string>
#include <vector>

namespace vtrack::testing {

class Subprocess {
 public:
  // Starts argv[0] (searched in PATH) with argv; stdout and stderr go to log_path if not empty.
  // Throws std::runtime_error if it cannot be started.
  explicit Subprocess(const std::vector<std::string>& argv, const std::string& log_path = "",
                      const std::vector<std::string>& extra_env = {});
  ~Subprocess();
  Subprocess(const Subprocess&) = delete;
  Subprocess& operator=(const Subprocess&) = delete;

  pid_t pid() const { return pid_; }
  bool Running();
  void Signal(int sig);
  // Waits for exit up to timeout; returns the exit status (128 + signal if killed), or nullopt.
  std::optional<int> Wait(std::chrono::milliseconds timeout);
  // SIGTERM, wait up to timeout, then SIGKILL. Returns the exit status.
  int Stop(std::chrono::milliseconds timeout = std::chrono::milliseconds(3000));

 private:
  pid_t pid_ = -1;
  std::optional<int> status_;
};

// Runs a command to completion (stdout+stderr to log_path); returns the exit status.
int RunCommand(const std::vector<std::string>& argv, const std::string& log_path = "",
               std::chrono::milliseconds timeout = std::chrono::milliseconds(120000));

// Reads a whole text file ("" if missing).
std::string ReadFile(const std::string& path);

}  // namespace vtrack::testing
