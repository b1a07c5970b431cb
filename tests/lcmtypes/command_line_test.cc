// The command-line checks the tools share (lcmtypes/util/command_line.h): an output that names an
// input, or another output, is refused, however the two paths are spelled; outputs that are not
// files (standard output, a device) are never refused.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "lcmtypes/util/command_line.h"
#include "tests/support/test_env.h"

namespace vtrack::lcm_util {
namespace {

namespace fs = std::filesystem;
namespace po = boost::program_options;

// The message of the refusal, or "" if the arguments are accepted.
std::string Refusal(const std::vector<PathArgument>& inputs, const std::vector<PathArgument>& outputs) {
  try {
    RefuseOverwritingInputs(inputs, outputs);
  } catch (const po::error& e) {
    return e.what();
  }
  return "";
}

TEST(CommandLineTest, AnOutputThatIsAnInputIsRefusedHoweverItIsSpelled) {
  const std::string dir = testing::ScratchDir("command_line");
  const std::string in = dir + "/run.lcm";
  std::ofstream(in) << "log";
  fs::create_directories(dir + "/sub");
  fs::remove(dir + "/link.lcm");
  fs::create_symlink("run.lcm", dir + "/link.lcm");
  fs::remove(dir + "/hard.lcm");
  fs::create_hard_link(in, dir + "/hard.lcm");
  for (const std::string& out : {in, dir + "/sub/../run.lcm", dir + "/./run.lcm", dir + "/link.lcm",
                                 dir + "/hard.lcm"}) {
    const std::string why = Refusal({{"--input", in}}, {{"--output", out}});
    EXPECT_NE(why.find("is also the input --input"), std::string::npos) << out << ": " << why;
    EXPECT_NE(why.find(out), std::string::npos) << why;
  }
  // The relative spelling, from the working directory.
  const fs::path cwd = fs::current_path();
  fs::current_path(dir);
  EXPECT_NE(Refusal({{"", "run.lcm"}}, {{"--out", in}}), "");
  fs::current_path(cwd);
  // Another file, an output not there yet, and outputs that are not files: accepted.
  EXPECT_EQ(Refusal({{"--input", in}}, {{"--output", dir + "/tracks.lcm"}}), "");
  EXPECT_EQ(Refusal({{"--input", in}, {"--config", ""}}, {{"--output", "-"}, {"--csv", ""}}), "");
  EXPECT_EQ(Refusal({{"--input", "/dev/null"}}, {{"--output", "/dev/null"}}), "");
}

TEST(CommandLineTest, TwoOutputsOnOneFileAreRefused) {
  const std::string dir = testing::ScratchDir("command_line");
  const std::string why = Refusal({}, {{"--output", dir + "/o.lcm"}, {"--evidence-csv", dir + "/sub/../o.lcm"}});
  EXPECT_NE(why.find("are the same file"), std::string::npos) << why;
  EXPECT_NE(why.find("--evidence-csv"), std::string::npos) << why;
  EXPECT_EQ(Refusal({}, {{"--output", dir + "/o.lcm"}, {"--evidence-csv", dir + "/o.csv"}}), "");
}

}  // namespace
}  // namespace vtrack::lcm_util
