#include "tests/support/lcm_log.h"

#include <gtest/gtest.h>
#include <signal.h>

#include <thread>

#include "lcmtypes/util/log_reader.h"
#include "tests/support/test_env.h"

namespace vtrack::testing {

std::vector<LoggedEvent> ReadLogEvents(const std::string& path) {
  std::vector<LoggedEvent> events;
  lcm_util::LogReader r(path);
  while (const lcm::LogEvent* e = r.Next()) {
    events.push_back({e->timestamp, e->channel,
                      std::string(static_cast<const char*>(e->data),
                                  static_cast<std::size_t>(e->datalen))});
  }
  return events;
}

void StopLogger(Subprocess* logger, std::chrono::milliseconds flush) {
  std::this_thread::sleep_for(flush);
  logger->Signal(SIGINT);
  const auto st = logger->Wait(std::chrono::milliseconds(5000));
  ASSERT_TRUE(st.has_value()) << "lcm-logger did not stop on SIGINT";
}

void RecordDriverAndEgoPose(const std::string& dir, const std::vector<std::string>& common,
                            const std::string& logger_url, const std::string& log,
                            std::chrono::milliseconds limit, std::chrono::milliseconds flush,
                            const std::vector<std::string>& driver_only) {
  Subprocess logger({"lcm-logger", "-q", "-f", "--lcm-url=" + logger_url, log}, dir + "/logger.txt");
  std::vector<std::string> d{BinDir() + "/vtrack-ladar-driver"}, e{BinDir() + "/vtrack-ego-pose"};
  d.insert(d.end(), common.begin(), common.end());
  d.insert(d.end(), driver_only.begin(), driver_only.end());
  e.insert(e.end(), common.begin(), common.end());
  Subprocess driver(d, dir + "/driver.txt");
  Subprocess ego(e, dir + "/ego.txt");
  const auto d_st = driver.Wait(limit), e_st = ego.Wait(limit);
  ASSERT_TRUE(d_st.has_value() && e_st.has_value()) << "the run did not end on time";
  EXPECT_EQ(*d_st, 0) << ReadFile(dir + "/driver.txt");
  EXPECT_EQ(*e_st, 0) << ReadFile(dir + "/ego.txt");
  StopLogger(&logger, flush);
}

}  // namespace vtrack::testing
