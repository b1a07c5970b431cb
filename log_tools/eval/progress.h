// Progress of long jobs on stderr: a bar redrawn in place on a terminal, or a line every 10 %
// when stderr is a file or pipe (so logs of CI runs stay short).
#pragma once

#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <string>

namespace vtrack::eval {

// Logs smaller than this are read in a moment: no progress output for them.
inline constexpr std::uintmax_t kProgressMinBytes = 32u << 20;

inline bool WorthProgress(const std::string& path) {
  std::error_code ec;
  const auto size = std::filesystem::file_size(path, ec);
  return !ec && size >= kProgressMinBytes;
}

class Progress {
 public:
  explicit Progress(bool enabled) : enabled_(enabled), tty_(::isatty(STDERR_FILENO) != 0) {}

  void Update(const std::string& label, double fraction) {
    if (!enabled_) return;
    const int percent = fraction <= 0.0 ? 0 : fraction >= 1.0 ? 100 : static_cast<int>(fraction * 100.0);
    if (label != label_) {
      Finish();
      label_ = label;
      last_percent_ = -1;
    }
    if (tty_) {
      if (percent == last_percent_) return;
      constexpr int kWidth = 30;
      const int filled = percent * kWidth / 100;
      std::fprintf(stderr, "\r[%s%s] %3d%% %s", std::string(filled, '#').c_str(),
                   std::string(kWidth - filled, ' ').c_str(), percent, label.c_str());
      open_line_ = true;
    } else {
      if (percent / 10 == last_percent_ / 10 && last_percent_ >= 0) return;
      std::fprintf(stderr, "%3d%% %s\n", percent / 10 * 10, label.c_str());
    }
    last_percent_ = percent;
    std::fflush(stderr);
  }
  // Ends the in-place line (call before printing anything else to stderr).
  void Finish() {
    if (open_line_) std::fputc('\n', stderr);
    open_line_ = false;
  }
  ~Progress() { Finish(); }

 private:
  bool enabled_;
  bool tty_;
  bool open_line_ = false;
  std::string label_;
  int last_percent_ = -1;
};

}  // namespace vtrack::eval
