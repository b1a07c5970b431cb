// tracks-compare on TRACKS logs written here with known differences: equal logs, a real field
// moved within and beyond the tolerance, a decision changed in a known message (named as the
// first that differs, with the largest differences before it), and unreadable input.
#include <gtest/gtest.h>

#include <lcm/lcm-cpp.hpp>

#include <regex>
#include <string>
#include <vector>

#include "tests/support/subprocess.h"
#include "tests/support/test_env.h"
#include "vtrack/track_list_t.hpp"

namespace vtrack::testing {
namespace {

// Five lists of two tracks each, 0.1 s apart.
std::vector<track_list_t> Lists() {
  std::vector<track_list_t> lists;
  for (int m = 0; m < 5; ++m) {
    track_list_t l;
    l.utime = 1'700'000'000'000'000 + 100'000 * m;
    l.scan_seq = m;
    l.mode = "mht";
    for (int k = 0; k < 2; ++k) {
      track_t t{};
      t.id = k + 1;
      t.status = track_t::STATUS_CONFIRMED;
      t.model = track_t::MODEL_ISM;
      t.object_class = track_t::CLASS_VEHICLE;
      t.x = 10.0 * k + m;
      t.y = -3.0;
      t.length = 4.5;
      t.width = 1.8;
      t.num_hypotheses = 1;
      t.num_updates = m + 1;
      t.npred = 0;
      l.tracks.push_back(t);
    }
    l.num_tracks = static_cast<std::int32_t>(l.tracks.size());
    lists.push_back(l);
  }
  return lists;
}

std::string Write(const std::string& path, const std::vector<track_list_t>& lists) {
  lcm::LogFile log(path, "w");
  for (std::size_t m = 0; m < lists.size(); ++m) {
    std::vector<char> buf(static_cast<std::size_t>(lists[m].getEncodedSize()));
    EXPECT_GT(lists[m].encode(buf.data(), 0, static_cast<int>(buf.size())), 0);
    lcm::LogEvent ev;
    ev.eventnum = static_cast<std::int64_t>(m);
    ev.timestamp = lists[m].utime;
    ev.channel = "TRACKS";
    ev.datalen = static_cast<std::int32_t>(buf.size());
    ev.data = buf.data();
    EXPECT_EQ(log.writeEvent(&ev), 0);
  }
  return path;
}

struct Result {
  int rc;
  std::string out;
};

Result Compare(const std::string& dir, const std::string& a, const std::string& b,
               std::vector<std::string> extra = {}) {
  std::vector<std::string> argv = {TRACKS_COMPARE, a, b};
  argv.insert(argv.end(), extra.begin(), extra.end());
  const int rc = RunCommand(argv, dir + "/out.txt");
  return {rc, ReadFile(dir + "/out.txt")};
}

// The largest position difference printed in text (its first "x_y" line), -1 if none.
double XyDiff(const std::string& text) {
  std::smatch m;
  return std::regex_search(text, m, std::regex(R"(x_y\s+([-+.0-9eE]+))")) ? std::stod(m[1]) : -1.0;
}

TEST(TracksCompareTest, EqualLogsAndARealFieldWithinAndBeyondTheTolerance) {
  const std::string dir = ScratchDir("tracks_compare_real");
  const std::string a = Write(dir + "/a.lcm", Lists());
  EXPECT_EQ(Compare(dir, a, a).rc, 0);

  auto lists = Lists();
  lists[3].tracks[1].x += 5e-4;
  const std::string b = Write(dir + "/b.lcm", lists);
  const Result bit = Compare(dir, a, b);
  EXPECT_EQ(bit.rc, 1) << bit.out;
  EXPECT_NE(bit.out.find("0 with different decisions"), std::string::npos) << bit.out;
  EXPECT_EQ(bit.out.find("first decision differing"), std::string::npos) << bit.out;
  EXPECT_EQ(Compare(dir, a, b, {"--tolerance", "1e-3"}).rc, 0);
  EXPECT_EQ(Compare(dir, a, b, {"--tolerance", "1e-4"}).rc, 1);
}

TEST(TracksCompareTest, NamesTheFirstMessageWhoseDecisionsDifferAndTheDifferencesBeforeIt) {
  const std::string dir = ScratchDir("tracks_compare_decision");
  const std::string a = Write(dir + "/a.lcm", Lists());
  auto lists = Lists();
  lists[1].tracks[1].x += 2e-4;                            // before: a real field
  lists[2].tracks[0].status = track_t::STATUS_COASTING;  // the first decision differing
  lists[3].tracks[1].object_class = track_t::CLASS_OTHER;
  lists[4].tracks[0].x += 0.5;                             // after: in the totals only
  const Result r = Compare(dir, a, Write(dir + "/b.lcm", lists), {"--tolerance", "1"});
  EXPECT_EQ(r.rc, 1) << r.out;
  EXPECT_NE(r.out.find("2 with different decisions"), std::string::npos) << r.out;
  const std::size_t first =
      r.out.find("first decision differing is in message 2 (utime 1700000000200000)");
  ASSERT_NE(first, std::string::npos) << r.out;
  const std::size_t all = r.out.find("all messages:");
  ASSERT_NE(all, std::string::npos) << r.out;
  // Before message 2 positions differ by 2e-4 m; over all messages by 0.5 m.
  EXPECT_NEAR(XyDiff(r.out.substr(first, all - first)), 2e-4, 1e-9) << r.out;
  EXPECT_NEAR(XyDiff(r.out.substr(all)), 0.5, 1e-9) << r.out;
}

TEST(TracksCompareTest, UnreadableOrMissingLogsAreRefused) {
  const std::string dir = ScratchDir("tracks_compare_bad");
  const std::string a = Write(dir + "/a.lcm", Lists());
  EXPECT_EQ(Compare(dir, a, dir + "/missing.lcm").rc, 2);
  EXPECT_EQ(RunCommand({TRACKS_COMPARE, a}, dir + "/usage.txt"), 2);
  EXPECT_EQ(Compare(dir, a, a, {"--tolerance", "-1"}).rc, 2);
}

}  // namespace
}  // namespace vtrack::testing
