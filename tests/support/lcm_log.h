// LCM logs in tests: reading back what lcm-logger or vtrack-sim-log wrote, and recording the live
// sensor processes with lcm-logger.
#pragma once

#include <chrono>
#include <cstdint>
#include <string>
#include <vector>

#include "tests/support/subprocess.h"

namespace vtrack::testing {

// The bus of the tests that run inside a private loopback-only network namespace: multicast that
// does not leave the host (ttl=0).
inline constexpr char kTestBusUrl[] = "udpm://239.255.76.67:7667?ttl=0";

// One event of a log file as stored.
struct LoggedEvent {
  std::int64_t timestamp;  // when it was logged [us]
  std::string channel;
  std::string data;  // the encoded message
};

// Every event of the log at path, in file order.
std::vector<LoggedEvent> ReadLogEvents(const std::string& path);

// Stops lcm-logger the way a user does (Ctrl-C), after `flush` for the last datagrams, so that it
// writes them out. A fatal failure if it has not stopped within 5 s.
void StopLogger(Subprocess* logger, std::chrono::milliseconds flush);

// vtrack-ladar-driver and vtrack-ego-pose (from BinDir()) run with the same options `common` while
// lcm-logger, on logger_url, records into `log`; both must end within `limit` with status 0, then
// the logger is stopped (StopLogger). Outputs go to dir/driver.txt, dir/ego.txt, dir/logger.txt.
// Failures are fatal: callers check HasFatalFailure(). driver_only: options for the driver alone.
void RecordDriverAndEgoPose(const std::string& dir, const std::vector<std::string>& common,
                            const std::string& logger_url, const std::string& log,
                            std::chrono::milliseconds limit, std::chrono::milliseconds flush,
                            const std::vector<std::string>& driver_only = {});

}  // namespace vtrack::testing
