// The LCM log reader on whole and damaged logs. Logs are written with liblcm's own writer
// (lcm::LogFile), then damaged byte by byte at offsets computed here from the lcm-logger format
// (28-byte header + channel + data per event); liblcm's reader is the reference on whole logs.
#include <gtest/gtest.h>

#include <lcm/lcm-cpp.hpp>

#include <cstdint>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "lcmtypes/util/log_reader.h"
#include "tests/support/test_env.h"

namespace vtrack::lcm_util {
namespace {

constexpr int kHeader = 28;

struct Written {
  std::string path;
  std::vector<std::int64_t> event_start;  // [bytes] offset of each event
  std::int64_t size = 0;
};

// n events on channel "CH<i>" with i + 10 data bytes each.
Written WriteLog(const std::string& name, int n) {
  Written w;
  w.path = testing::ScratchDir("log_reader") + "/" + name;
  lcm::LogFile log(w.path, "w");
  std::int64_t offset = 0;
  for (int i = 0; i < n; ++i) {
    std::string data(static_cast<std::size_t>(i + 10), static_cast<char>('a' + i % 26));
    lcm::LogEvent ev;
    ev.eventnum = i;
    ev.timestamp = 1000 * i;
    ev.channel = "CH" + std::to_string(i);
    ev.datalen = static_cast<std::int32_t>(data.size());
    ev.data = data.data();
    EXPECT_EQ(log.writeEvent(&ev), 0);
    w.event_start.push_back(offset);
    offset += kHeader + static_cast<std::int64_t>(ev.channel.size()) + ev.datalen;
  }
  w.size = offset;
  return w;
}

std::string Bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}
void Put(const std::string& path, const std::string& bytes) {
  std::ofstream(path, std::ios::binary | std::ios::trunc) << bytes;
}

std::vector<std::string> Channels(LogReader* r) {
  std::vector<std::string> out;
  while (const lcm::LogEvent* ev = r->Next()) out.push_back(ev->channel);
  return out;
}

TEST(LogReaderTest, WholeLogReadsAsLiblcmReadsIt) {
  const Written w = WriteLog("whole.lcm", 20);
  lcm::LogFile ref(w.path, "r");
  LogReader r(w.path);
  int n = 0;
  while (const lcm::LogEvent* ev = r.Next()) {
    const lcm::LogEvent* e = ref.readNextEvent();
    ASSERT_NE(e, nullptr);
    EXPECT_EQ(ev->eventnum, e->eventnum);
    EXPECT_EQ(ev->timestamp, e->timestamp);
    EXPECT_EQ(ev->channel, e->channel);
    ASSERT_EQ(ev->datalen, e->datalen);
    EXPECT_EQ(std::string(static_cast<const char*>(ev->data), ev->datalen),
              std::string(static_cast<const char*>(e->data), e->datalen));
    ++n;
  }
  EXPECT_EQ(ref.readNextEvent(), nullptr);
  EXPECT_EQ(n, 20);
  EXPECT_FALSE(r.damaged());
  EXPECT_EQ(r.DamageSummary(), "");
  EXPECT_EQ(r.BytesRead(), w.size);
}

// A data length of 0x7fffffff (liblcm 1.3.1 crashes on it) mid-log: that event is skipped, the
// rest is read.
// The writer's byte count is the size of the file it leaves (read back by the file system).
TEST(LogWriterTest, BytesWrittenIsTheFileSize) {
  const std::string path = testing::ScratchDir("log_reader") + "/count.lcm";
  std::int64_t counted = 0;
  {
    LogWriter w(path);
    for (int i = 0; i < 7; ++i) {
      const std::string data(static_cast<std::size_t>(100 * i), 'x');
      w.Write(1000 * i, "CHANNEL_" + std::to_string(i), data.data(), data.size());
    }
    counted = w.bytes_written();
    EXPECT_EQ(w.events_written(), 7);
  }
  EXPECT_EQ(counted, static_cast<std::int64_t>(Bytes(path).size()));
  EXPECT_GT(counted, 7 * kHeader + 2100);
}

// What is not a log is said for what it is.
TEST(LogReaderTest, AMissingFileOrADirectoryIsNamed) {
  const std::string dir = testing::ScratchDir("log_reader");
  const auto message = [](const std::string& path) {
    try {
      LogReader r(path);
    } catch (const std::runtime_error& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_EQ(message(dir + "/missing.lcm"), "cannot open LCM log '" + dir + "/missing.lcm': no such file");
  EXPECT_EQ(message(dir), "cannot open LCM log '" + dir + "': a directory, not a log file");
}

TEST(LogReaderTest, ImpossibleLengthIsSkippedToTheNextEvent) {
  const Written w = WriteLog("length.lcm", 10);
  std::string b = Bytes(w.path);
  const std::size_t at = static_cast<std::size_t>(w.event_start[4]) + 24;
  b[at] = '\x7f'; b[at + 1] = b[at + 2] = b[at + 3] = '\xff';
  Put(w.path, b);
  LogReader r(w.path);
  const auto ch = Channels(&r);
  ASSERT_EQ(ch.size(), 9u);
  EXPECT_EQ(ch[3], "CH3");
  EXPECT_EQ(ch[4], "CH5");
  EXPECT_TRUE(r.damaged());
  EXPECT_EQ(r.damage().regions, 1);
  EXPECT_EQ(r.damage().first_offset, w.event_start[4]);
  EXPECT_EQ(r.damage().bytes_skipped, w.event_start[5] - w.event_start[4]);
  EXPECT_FALSE(r.damage().truncated);
}

TEST(LogReaderTest, GarbageBetweenEventsIsSkippedAndSaidWhere) {
  const Written w = WriteLog("garbage.lcm", 10);
  std::string b = Bytes(w.path);
  // 37 bytes of garbage, one of them the sync word's first byte, before event 6.
  const std::string garbage = "\xed" + std::string(36, 'x');
  b.insert(static_cast<std::size_t>(w.event_start[6]), garbage);
  Put(w.path, b);
  LogReader r(w.path);
  EXPECT_EQ(Channels(&r).size(), 10u);
  EXPECT_EQ(r.damage().regions, 1);
  EXPECT_EQ(r.damage().first_offset, w.event_start[6]);
  EXPECT_EQ(r.damage().bytes_skipped, 37);
  EXPECT_NE(r.DamageSummary().find("37 bytes in 1 place(s) skipped, the first at byte " +
                                   std::to_string(w.event_start[6])),
            std::string::npos)
      << r.DamageSummary();
}

TEST(LogReaderTest, LogCutInAnEventIsTruncated) {
  const Written w = WriteLog("cut.lcm", 10);
  std::string b = Bytes(w.path);
  b.resize(static_cast<std::size_t>(w.event_start[9] + 30));  // header and a little of event 9
  Put(w.path, b);
  LogReader r(w.path);
  EXPECT_EQ(Channels(&r).size(), 9u);
  EXPECT_TRUE(r.damage().truncated);
  EXPECT_EQ(r.damage().first_offset, w.event_start[9]);
  EXPECT_EQ(r.damage().bytes_skipped, 30);
  EXPECT_NE(r.DamageSummary().find("(cut short at the end); 9 whole events read"), std::string::npos)
      << r.DamageSummary();
}

// The 126-byte file that crashed the tools through liblcm: one header claiming 0x7fffffff bytes.
TEST(LogReaderTest, LoneHeaderWithHugeLengthReadsNothing) {
  const std::string path = testing::ScratchDir("log_reader") + "/crash.lcm";
  std::string b = std::string("\xed\xa1\xda\x01", 4) + std::string(16, '\0') +
                  std::string("\x00\x00\x00\x0a\x7f\xff\xff\xff", 8) + "LADAR_SCAN" +
                  std::string(100, 'x');
  Put(path, b);
  LogReader r(path);
  EXPECT_EQ(r.Next(), nullptr);
  EXPECT_TRUE(r.damage().truncated);
  EXPECT_EQ(r.damage().bytes_skipped, 138);
}

TEST(LogReaderTest, RandomBytesAreSaidToHoldNoEvent) {
  const std::string path = testing::ScratchDir("log_reader") + "/random.bin";
  std::string b(5000, '\0');
  std::uint32_t state = 12345;  // a fixed linear congruential sequence: the same bytes each run
  for (char& c : b) {
    state = state * 1664525u + 1013904223u;
    c = static_cast<char>(state >> 24);
  }
  Put(path, b);
  LogReader r(path);
  EXPECT_EQ(r.Next(), nullptr);
  EXPECT_EQ(r.damage().bytes_skipped, 5000);
  EXPECT_EQ(r.DamageSummary(), "log '" + path +
                                   "' holds no LCM event: none of its 5000 bytes starts a whole "
                                   "one (not an LCM log, or one cut short within its first event)");
  // A log whose first event is whole is damaged, not empty, whatever follows.
  const Written w = WriteLog("one_then_random.lcm", 1);
  Put(w.path, Bytes(w.path) + b);
  LogReader one(w.path);
  EXPECT_NE(one.Next(), nullptr);
  EXPECT_EQ(one.Next(), nullptr);
  EXPECT_NE(one.DamageSummary().find("(cut short at the end); 1 whole events read"),
            std::string::npos)
      << one.DamageSummary();
}

}  // namespace
}  // namespace vtrack::lcm_util
