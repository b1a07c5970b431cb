// vtrack-monitor: a terminal view of an LCM bus or log (lcm-spy is a GUI; vehicles are headless).
// See log_tools/README.md.
#include <sys/ioctl.h>
#include <unistd.h>

#include <boost/program_options.hpp>
#include <lcm/lcm-cpp.hpp>
#include <lcm/lcm.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <regex>
#include <string>

#include "lcmtypes/util/command_line.h"
#include "lcmtypes/util/log_reader.h"
#include "lcmtypes/util/process.h"
#include "log_tools/monitor/monitor.h"

namespace po = boost::program_options;
using vtrack::monitor::ChannelTable;

namespace {

constexpr const char* kLcmDefaultUrl = "udpm://239.255.76.67:7667?ttl=0";  // LCM 1.3's default
constexpr const char* kRecvBuf = "recv_buf_size=4194304";

// The URL to open: as given, else $LCM_DEFAULT_URL, else LCM's default; a udpm:// URL without
// recv_buf_size gets one (docs/design.md, section 8: 2 MB scans are lost with the default socket buffer).
std::string LiveUrl(const std::string& given) {
  std::string url = given;
  if (url.empty()) {
    const char* env = std::getenv("LCM_DEFAULT_URL");
    url = (env && *env) ? env : kLcmDefaultUrl;
  }
  if (url.rfind("udpm://", 0) == 0 && url.find("recv_buf_size") == std::string::npos) {
    url += (url.find('?') == std::string::npos ? "?" : "&");
    url += kRecvBuf;
  }
  return url;
}

int TerminalWidth() {
  winsize ws{};
  if (::isatty(STDOUT_FILENO) && ::ioctl(STDOUT_FILENO, TIOCGWINSZ, &ws) == 0 && ws.ws_col > 0) {
    return ws.ws_col;
  }
  return 0;  // not a terminal: full lines
}

std::int64_t NowUs() {
  return std::chrono::duration_cast<std::chrono::microseconds>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

std::string Header(const std::string& source, double elapsed_s, const ChannelTable& table) {
  char buf[256];
  std::snprintf(buf, sizeof(buf), "vtrack-monitor  %s  %.1f s  %lld messages  %.2f MB\n",
                source.c_str(), elapsed_s, static_cast<long long>(table.total_messages()),
                table.total_bytes() / 1e6);
  return buf;
}

// Called by LCM for every message: the receive time on this machine's monotonic clock, since live
// rates are about arrival. Never lets an exception escape into LCM's C code.
void OnMessage(const lcm_recv_buf_t* rbuf, const char* channel, void* user) {
  try {
    static_cast<ChannelTable*>(user)->Add(channel, NowUs(), rbuf->data, rbuf->data_size);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "vtrack-monitor: %s\n", e.what());
  }
}

int RunLog(const std::string& path, const std::string& channels, int width) {
  vtrack::lcm_util::LogReader reader(path);
  const std::regex re(channels, std::regex::extended);
  ChannelTable table;
  const bool tty = ::isatty(STDERR_FILENO);
  std::int64_t first = -1, last = 0, events = 0;
  int last_percent = -1;
  while (const lcm::LogEvent* ev = reader.Next()) {
    if (!std::regex_match(ev->channel, re)) continue;
    first = first < 0 ? ev->timestamp : std::min<std::int64_t>(first, ev->timestamp);
    last = std::max<std::int64_t>(last, ev->timestamp);
    table.Add(ev->channel, ev->timestamp, ev->data,
              static_cast<std::size_t>(std::max<std::int32_t>(ev->datalen, 0)));
    if (reader.FileSize() > (64 << 20) && (++events % 256) == 0) {
      const int percent = static_cast<int>(100.0 * reader.BytesRead() / reader.FileSize());
      if (percent / 10 != last_percent / 10) {
        std::fprintf(stderr, tty ? "\rreading %s: %d%%" : "reading %s: %d%%\n", path.c_str(), percent);
        last_percent = percent;
      }
    }
  }
  if (last_percent >= 0 && tty) std::fputc('\n', stderr);
  const double span = first >= 0 ? (last - first) * 1e-6 : 0.0;
  std::cout << Header(path, span, table) << table.Render(last, /*whole_span=*/true, width);
  if (reader.damaged()) {
    std::fprintf(stderr, "vtrack-monitor: %s\n", reader.DamageSummary().c_str());
    return 3;
  }
  return 0;
}

int RunLive(const std::string& url, const std::string& channels, double duration_s,
            double interval_s, bool once, int width) {
  auto lcm = vtrack::lcm_util::OpenLcm(url);
  ChannelTable table(std::max(2.0, interval_s));
  // Through LCM's C API: the C++ untyped-handler trampoline of Debian's LCM 1.3.1 hands its
  // callback a pointer that UBSan's vptr check rejects, so sanitized builds would abort.
  if (!lcm_subscribe(lcm->getUnderlyingLCM(), channels.c_str(), &OnMessage, &table)) {
    throw std::runtime_error("cannot subscribe to '" + channels + "'");
  }
  vtrack::lcm_util::InstallStopHandlers();
  const bool tty = ::isatty(STDOUT_FILENO);
  const std::int64_t start = NowUs();
  const auto deadline_us = duration_s > 0.0 ? start + static_cast<std::int64_t>(duration_s * 1e6) : 0;
  std::int64_t next_draw = start + static_cast<std::int64_t>(interval_s * 1e6);
  std::fprintf(stderr, "vtrack-monitor: listening on %s (channels matching '%s')\n", url.c_str(),
               channels.c_str());
  while (!vtrack::lcm_util::StopRequested()) {
    const std::int64_t now = NowUs();
    if (deadline_us > 0 && now >= deadline_us) break;
    if (!once && now >= next_draw) {
      std::cout << (tty ? "\033[H\033[2J" : "") << Header(url, (now - start) * 1e-6, table)
                << table.Render(now, false, width) << (tty ? "" : "\n") << std::flush;
      next_draw = now + static_cast<std::int64_t>(interval_s * 1e6);
    }
    if (lcm->handleTimeout(50) < 0) {
      std::fprintf(stderr, "vtrack-monitor: LCM receive failed on %s\n", url.c_str());
      return 1;
    }
  }
  const std::int64_t now = NowUs();
  std::cout << (tty && !once ? "\033[H\033[2J" : "") << Header(url, (now - start) * 1e-6, table)
            << table.Render(now, false, width) << std::flush;
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  std::string url, input, channels = ".*";
  double duration_s = 0.0, interval_s = 1.0;
  bool once = false;
  int width = -1;
  po::options_description desc(
      "vtrack-monitor [--input LOG] [options]\n"
      "A terminal view of the LCM bus (or of a log): per channel the message type, count, rate,\n"
      "bandwidth, decode errors and a one-line summary of the latest vtrack message.\n\nOptions");
  desc.add_options()
    ("help,h", "print this help")
    ("lcm-url", po::value(&url), "LCM URL (default: $LCM_DEFAULT_URL or LCM's default); "
                                 "recv_buf_size=4194304 is added to a udpm:// URL that has none")
    ("input,i", po::value(&input), "read this LCM log instead of the bus, print one table and exit "
                                   "(rates from the log's timestamps)")
    ("channels", po::value(&channels)->default_value(channels), "channel regular expression")
    ("duration", po::value(&duration_s)->default_value(duration_s),
     "[s] live: stop after this long and print the final table (0 = until Ctrl-C)")
    ("interval", po::value(&interval_s)->default_value(interval_s), "[s] live: table refresh period")
    ("once", po::bool_switch(&once), "live: print a single table at the end (after --duration, "
                                     "1 s if not given); for scripts")
    ("width", po::value(&width)->default_value(width),
     "cut lines to this many characters (-1 = the terminal's width, 0 = no limit)");
  try {
    po::variables_map vm;
    if (!vtrack::lcm_util::StoreCommandLine(po::parse_command_line(argc, argv, desc), desc, &vm)) {
      return 0;
    }
    if (!(duration_s >= 0.0) || !std::isfinite(duration_s)) {
      throw std::invalid_argument("--duration must be >= 0, got " + std::to_string(duration_s));
    }
    if (!(interval_s > 0.0) || !std::isfinite(interval_s)) {
      throw std::invalid_argument("--interval must be > 0, got " + std::to_string(interval_s));
    }
    if (width < -1) throw std::invalid_argument("--width must be >= -1, got " + std::to_string(width));
    try {
      std::regex(channels, std::regex::extended);
    } catch (const std::regex_error& e) {
      throw std::invalid_argument("--channels: bad regular expression '" + channels + "'");
    }
    if (!input.empty() && !url.empty()) {
      throw std::invalid_argument("--input and --lcm-url exclude each other");
    }
  } catch (const std::exception& e) {
    std::cerr << "vtrack-monitor: " << e.what() << "\n";
    return 2;
  }
  if (width < 0) width = TerminalWidth();
  try {
    if (!input.empty()) return RunLog(input, channels, width);
    if (once && duration_s == 0.0) duration_s = 1.0;
    return RunLive(LiveUrl(url), channels, duration_s, interval_s, once, width);
  } catch (const std::exception& e) {
    std::cerr << "vtrack-monitor: " << e.what() << "\n";
    return 1;
  }
}
