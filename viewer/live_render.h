// Live rendering from the LCM bus. The LCM thread (the caller's) only decodes messages and puts
// frames together; a render thread draws the newest complete frame and hands it to a sink (video,
// PNG). When drawing falls behind, frames that were never drawn are replaced by newer ones and
// counted as dropped: the renderer never slows the bus or the tracker.
#pragma once

#include <lcm/lcm-cpp.hpp>

#include <atomic>
#include <chrono>
#include <cstdint>
#include <functional>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "viewer/latest_slot.h"
#include "viewer/message_router.h"
#include "viewer/render_job.h"

namespace vtrack::viewer {

// The URL with recv_buf_size=4194304 added for a udpm:// URL that sets none (docs/design.md, section 8:
// without a large socket buffer most 2 MB scans are lost). "" means $LCM_DEFAULT_URL, or LCM's
// default udpm://239.255.76.67:7667?ttl=0. Other providers (memq://, file://) are unchanged.
std::string WithReceiveBuffer(const std::string& url);

struct LiveStats {
  std::int64_t messages = 0;         // messages decoded on the renderer's channels
  std::int64_t frames_ready = 0;     // frames put together from the bus
  std::int64_t frames_rendered = 0;  // drawn and handed to the sink
  std::int64_t frames_dropped = 0;   // replaced by a newer frame before they could be drawn
  std::int64_t frames_skipped = 0;   // outside [start, end]
  std::int64_t tracks_received = 0;  // TRACKS messages decoded
  std::int64_t tracks_late = 0;      // of them, too late for a frame of their own, in order
                                     // (AssemblerStats::late_tracks)
  std::int64_t decode_errors = 0;
};

class LiveRenderer {
 public:
  using Sink = std::function<void(const Scene& scene, const cv::Mat& image)>;

  // Subscribes to the job's channels and starts the render thread. Throws std::invalid_argument
  // if the job is invalid. idle_flush: when no message has come for this long, the frames still
  // waiting for late parts are drawn (the end of a replay).
  LiveRenderer(lcm::LCM* lcm, const RenderJob& job, Sink sink,
               std::chrono::milliseconds idle_flush = std::chrono::milliseconds(500));
  ~LiveRenderer();
  LiveRenderer(const LiveRenderer&) = delete;
  LiveRenderer& operator=(const LiveRenderer&) = delete;

  // Handles the bus for up to timeout_ms (call it in a loop on the LCM thread). Returns false if
  // LCM reported an error.
  bool HandleOnce(int timeout_ms);
  // Draws what is pending, waits for the render thread to finish and joins it. Idempotent.
  void Finish();

  LiveStats stats() const;  // call on the LCM thread
  bool failed() const { return failed_.load(); }  // the sink or the renderer threw
  std::string error() const;
  bool done() const { return done_.load(); }      // max_frames reached

 private:
  void OnMessage(const lcm::ReceiveBuffer* rbuf, const std::string& channel);
  void Offer(std::vector<FrameInputs> frames);
  void RenderLoop();

  lcm::LCM* lcm_;
  RenderJob job_;
  Sink sink_;
  std::chrono::milliseconds idle_flush_;
  FrameAssembler assembler_;
  MessageRouter router_;
  std::vector<lcm::Subscription*> subscriptions_;
  std::chrono::steady_clock::time_point last_message_;
  LatestSlot<FrameInputs> slot_;
  std::thread render_thread_;
  bool finished_ = false;

  std::atomic<std::int64_t> frames_ready_{0};
  std::atomic<std::int64_t> frames_rendered_{0};
  std::atomic<std::int64_t> frames_skipped_{0};
  std::atomic<bool> failed_{false};
  std::atomic<bool> done_{false};
  mutable std::mutex error_mutex_;
  std::string error_;
};

}  // namespace vtrack::viewer
