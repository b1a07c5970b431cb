// Where rendered frames go: an MP4 video (cv::VideoWriter, FFmpeg backend, fourcc 'mp4v') and PNG
// snapshots every N frames and/or at given times. No LCM.
#pragma once

#include <opencv2/core.hpp>
#include <opencv2/videoio.hpp>

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "viewer/validate.h"

namespace vtrack::viewer {

struct OutputParams {
  std::string video_path;          // [-] video file (.mp4); "" = no video
  double fps = 0.0;                // [1/s] video frame rate; 0 = the scan rate, estimated from
                                   //       the first frames' times (median interval)
  std::string png_dir;             // [-] directory for PNG snapshots (created); "" = none
  int png_every = 0;               // [frames] a PNG every N frames, starting with the first; 0 = off
  std::vector<double> png_at_s;    // [s] a PNG of the first frame at or after each of these times
                                   //     (seconds since the first frame of the run)

  // True if every field is valid; otherwise false and *error names the key and its value.
  bool Validate(std::string* error) const { return ValidateByFirstProblem(*this, error); }
  std::string FirstProblem() const;  // "" if valid
};

class FrameOutput {
 public:
  // Creates png_dir if needed. Throws std::runtime_error naming the path if the PNG directory
  // cannot be created or the video's directory does not exist.
  explicit FrameOutput(const OutputParams& params);
  ~FrameOutput();
  FrameOutput(const FrameOutput&) = delete;
  FrameOutput& operator=(const FrameOutput&) = delete;

  // Adds the next frame (BGR, 8-bit; every frame the same size). time_s is seconds since the
  // first frame, utime the data time (for the frame rate estimate). Throws std::runtime_error if
  // the video cannot be opened or a PNG cannot be written.
  void Write(const cv::Mat& bgr, std::int64_t utime, double time_s);
  // Writes what is buffered and closes the video. Idempotent. Throws like Write.
  void Close();

  std::int64_t frames() const { return frames_; }                // frames given to Write
  std::int64_t video_frames() const { return video_frames_; }    // frames in the video so far
  const std::vector<std::string>& png_paths() const { return png_paths_; }
  double fps() const { return fps_; }  // 0 until known
  const OutputParams& params() const { return params_; }

 private:
  void OpenVideo(const cv::Size& size);
  void WriteVideo(const cv::Mat& bgr);
  double EstimateFps() const;

  OutputParams params_;
  cv::VideoWriter video_;
  bool closed_ = false;
  double fps_ = 0.0;
  cv::Size size_;
  std::int64_t frames_ = 0;
  std::int64_t video_frames_ = 0;
  std::size_t next_png_at_ = 0;
  std::vector<std::string> png_paths_;
  // Frames held back until the frame rate is known (only when fps = 0 and a video is wanted).
  std::vector<std::pair<std::int64_t, cv::Mat>> held_;
};

}  // namespace vtrack::viewer
