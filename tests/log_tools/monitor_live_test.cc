// vtrack-monitor live on a real LCM bus (udpm:// inside a private loopback-only network
// namespace: ctest runs this through scripts/vtrack-netns).
#include <gtest/gtest.h>

#include <lcm/lcm-cpp.hpp>

#include <chrono>
#include <filesystem>
#include <thread>

#include "tests/support/subprocess.h"
#include "tests/support/test_env.h"
#include "vtrack/pose_t.hpp"

namespace vtrack::testing {
namespace {

TEST(MonitorLiveTest, ShowsWhatIsPublished) {
  VTRACK_REQUIRE_PRIVATE_NETNS();
  const std::string exe = BinDir() + "/vtrack-monitor";
  if (!std::filesystem::exists(exe)) GTEST_SKIP() << exe << " is not built";
  const std::string url = "udpm://239.255.76.67:7667?ttl=0";
  lcm::LCM lcm(url);
  ASSERT_TRUE(lcm.good());
  const std::string dir = ScratchDir("monitor_live"), out = dir + "/out.txt";
  Subprocess monitor({exe, "--lcm-url", url, "--once", "--duration", "3", "--width", "0"}, out);
  vtrack::pose_t pose{};
  pose.pos[0] = 1.0;
  pose.pos[1] = 2.0;
  pose.pos[2] = 3.0;
  pose.orientation[0] = 1.0;
  // Publish until the monitor has finished (it stops by itself after 3 s).
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(20);
  while (monitor.Running() && std::chrono::steady_clock::now() < deadline) {
    lcm.publish("EGO_POSE", &pose);
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  const auto status = monitor.Wait(std::chrono::seconds(5));
  ASSERT_TRUE(status.has_value());
  EXPECT_EQ(*status, 0);
  const std::string text = ReadFile(out);
  EXPECT_NE(text.find("EGO_POSE"), std::string::npos) << text;
  EXPECT_NE(text.find("pose_t"), std::string::npos) << text;
  EXPECT_NE(text.find("pos (1.00, 2.00, 3.00) m"), std::string::npos) << text;
  EXPECT_NE(text.find("recv_buf_size=4194304"), std::string::npos) << text;  // added to the URL
}

}  // namespace
}  // namespace vtrack::testing
