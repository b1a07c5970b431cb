#include "tests/support/tool_test.h"

#include <chrono>
#include <filesystem>
#include <utility>

#include "tests/support/subprocess.h"
#include "tests/support/test_env.h"

namespace vtrack::testing {

ToolTest::ToolTest(std::string tool, std::string scratch)
    : exe_(BinDir() + "/" + tool), scratch_(std::move(scratch)) {}

void ToolTest::SetUp() {
  if (!std::filesystem::exists(exe_)) GTEST_SKIP() << exe_ << " is not built";
  dir_ = ScratchDir(scratch_);
  Prepare();
}

int ToolTest::RunTool(std::vector<std::string> args, std::string* output,
                      const std::vector<std::string>& env) {
  args.insert(args.begin(), exe_);
  const std::string log = dir_ + "/out.txt";
  Subprocess p(args, log, env);
  const auto rc = p.Wait(std::chrono::seconds(120));
  const int status = rc ? *rc : p.Stop();
  *output = ReadFile(log);
  return status;
}

}  // namespace vtrack::testing
