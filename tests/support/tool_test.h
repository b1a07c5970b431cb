// A fixture for tests that run one executable of the build (BinDir()/tool) as a process.
#pragma once

#include <gtest/gtest.h>

#include <string>
#include <vector>

namespace vtrack::testing {

class ToolTest : public ::testing::Test {
 protected:
  // tool: the executable's name in BinDir(); scratch: the name of the test's scratch directory.
  ToolTest(std::string tool, std::string scratch);

  // Skips the test when the tool is not built; else makes a fresh scratch directory, dir_, and
  // calls Prepare().
  void SetUp() final;

  // What a fixture derived from this one sets up in dir_ for each test.
  virtual void Prepare() {}

  // Runs the tool with args (and env added to the environment); its output (stdout and stderr,
  // kept in dir_/out.txt) is put in *output. Returns the exit status; a run that has not ended
  // within 120 s is stopped.
  int RunTool(std::vector<std::string> args, std::string* output,
              const std::vector<std::string>& env = {});

  std::string exe_;  // the tool's path
  std::string dir_;  // the scratch directory

 private:
  std::string scratch_;
};

}  // namespace vtrack::testing
