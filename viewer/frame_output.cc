#include "viewer/frame_output.h"

#include <opencv2/imgcodecs.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <sstream>
#include <stdexcept>

namespace vtrack::viewer {
namespace {

namespace fs = std::filesystem;

constexpr std::size_t kFpsWindow = 8;   // frames held to estimate the scan rate
constexpr double kDefaultFps = 10.0;    // [1/s] if the rate cannot be estimated (fewer than 2 frames)

}  // namespace

std::string OutputParams::FirstProblem() const {
  std::ostringstream os;
  if (!(fps >= 0.0) || !std::isfinite(fps) || fps > 1000.0) {
    os << "output.fps = " << fps << ": must be in [0, 1000] (0 = scan rate)";
    return os.str();
  }
  if (png_every < 0) {
    os << "output.png_every = " << png_every << ": must be >= 0 (0 = off)";
    return os.str();
  }
  for (double t : png_at_s) {
    if (!std::isfinite(t) || t < 0.0) {
      os << "output.png_at = " << t << ": times must be finite and >= 0 s";
      return os.str();
    }
  }
  if ((png_every > 0 || !png_at_s.empty()) && png_dir.empty()) {
    return "output.png_dir is empty: PNG snapshots were asked for (png_every / png_at) but no "
           "directory given";
  }
  return {};
}

FrameOutput::FrameOutput(const OutputParams& params) : params_(params) {
  if (const std::string err = params_.FirstProblem(); !err.empty()) throw std::invalid_argument(err);
  std::sort(params_.png_at_s.begin(), params_.png_at_s.end());
  std::error_code ec;
  if (!params_.png_dir.empty()) {
    fs::create_directories(params_.png_dir, ec);
    if (!fs::is_directory(params_.png_dir)) {
      throw std::runtime_error("cannot create PNG directory '" + params_.png_dir +
                               "': " + (ec ? ec.message() : std::string("not a directory")));
    }
  }
  if (!params_.video_path.empty()) {
    const fs::path dir = fs::absolute(params_.video_path, ec).parent_path();
    if (!fs::is_directory(dir)) {
      throw std::runtime_error("cannot write video '" + params_.video_path + "': directory '" +
                               dir.string() + "' does not exist");
    }
  }
  if (params_.fps > 0.0) fps_ = params_.fps;
}

FrameOutput::~FrameOutput() {
  try {
    Close();
  } catch (const std::exception& e) {
    std::fprintf(stderr, "vtrack-render: %s\n", e.what());
  }
}

void FrameOutput::Write(const cv::Mat& bgr, std::int64_t utime, double time_s) {
  if (closed_) throw std::logic_error("FrameOutput::Write after Close");
  if (bgr.empty() || bgr.type() != CV_8UC3) {
    throw std::invalid_argument("FrameOutput::Write: frame must be a non-empty 8-bit BGR image");
  }
  if (size_.empty()) size_ = bgr.size();
  if (bgr.size() != size_) {
    throw std::invalid_argument("FrameOutput::Write: frame size " + std::to_string(bgr.cols) +
                                "x" + std::to_string(bgr.rows) + " differs from the first frame's " +
                                std::to_string(size_.width) + "x" + std::to_string(size_.height));
  }
  const std::int64_t index = frames_++;

  bool png = params_.png_every > 0 && index % params_.png_every == 0;
  while (next_png_at_ < params_.png_at_s.size() && time_s >= params_.png_at_s[next_png_at_]) {
    png = true;
    ++next_png_at_;
  }
  if (png && !params_.png_dir.empty()) {
    char name[64];
    std::snprintf(name, sizeof(name), "frame_%06lld.png", static_cast<long long>(index));
    const std::string path = (fs::path(params_.png_dir) / name).string();
    bool ok = false;
    try {
      ok = cv::imwrite(path, bgr);
    } catch (const cv::Exception& e) {
      throw std::runtime_error("cannot write PNG '" + path + "': " + e.what());
    }
    if (!ok) throw std::runtime_error("cannot write PNG '" + path + "' (disk full? permissions?)");
    png_paths_.push_back(path);
  }

  if (params_.video_path.empty()) return;
  if (fps_ > 0.0) {
    WriteVideo(bgr);
    return;
  }
  held_.emplace_back(utime, bgr.clone());
  if (held_.size() >= kFpsWindow) {
    fps_ = EstimateFps();
    for (const auto& [t, img] : held_) WriteVideo(img);
    held_.clear();
  }
}

void FrameOutput::Close() {
  if (closed_) return;
  closed_ = true;
  if (!held_.empty()) {
    fps_ = EstimateFps();
    for (const auto& [t, img] : held_) WriteVideo(img);
    held_.clear();
  }
  if (video_.isOpened()) video_.release();
}

double FrameOutput::EstimateFps() const {
  std::vector<double> dt;
  for (std::size_t i = 1; i < held_.size(); ++i) {
    const double d = static_cast<double>(held_[i].first - held_[i - 1].first);
    if (d > 0.0) dt.push_back(d);
  }
  if (dt.empty()) return kDefaultFps;
  std::nth_element(dt.begin(), dt.begin() + dt.size() / 2, dt.end());
  return std::clamp(1e6 / dt[dt.size() / 2], 1.0, 240.0);
}

void FrameOutput::OpenVideo(const cv::Size& size) {
  const int fourcc = cv::VideoWriter::fourcc('m', 'p', '4', 'v');
  // The FFmpeg backend explicitly: Debian's OpenCV would otherwise try GStreamer first.
  video_.open(params_.video_path, cv::CAP_FFMPEG, fourcc, fps_, size, true);
  if (!video_.isOpened()) {
    std::ostringstream os;
    os << "cannot open video '" << params_.video_path << "' for writing (FFmpeg, fourcc mp4v, "
       << size.width << "x" << size.height << ", " << fps_
       << " fps): use a .mp4 or .avi name in a writable directory";
    throw std::runtime_error(os.str());
  }
}

void FrameOutput::WriteVideo(const cv::Mat& bgr) {
  if (!video_.isOpened()) OpenVideo(bgr.size());
  video_.write(bgr);
  ++video_frames_;
}

}  // namespace vtrack::viewer
