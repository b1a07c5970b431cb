#include "viewer/live_render.h"

#include <cstdlib>
#include <stdexcept>

#include "viewer/scene_builder.h"

namespace vtrack::viewer {

std::string WithReceiveBuffer(const std::string& url) {
  std::string u = url;
  if (u.empty()) {
    const char* env = std::getenv("LCM_DEFAULT_URL");
    u = (env && *env) ? env : "udpm://239.255.76.67:7667?ttl=0";
  }
  if (u.rfind("udpm://", 0) != 0 || u.find("recv_buf_size=") != std::string::npos) return u;
  return u + (u.find('?') == std::string::npos ? "?" : "&") + "recv_buf_size=4194304";
}

LiveRenderer::LiveRenderer(lcm::LCM* lcm, const RenderJob& job, Sink sink,
                           std::chrono::milliseconds idle_flush)
    : lcm_(lcm),
      job_(job),
      sink_(std::move(sink)),
      idle_flush_(idle_flush),
      assembler_(job.assembler),
      router_(job.channels, &assembler_),
      last_message_(std::chrono::steady_clock::now()) {
  if (const std::string err = job_.FirstProblem(); !err.empty()) throw std::invalid_argument(err);
  for (const std::string* ch : {&job_.channels.scan, &job_.channels.slice, &job_.channels.pose, &job_.channels.tracks,
                                &job_.channels.debug, &job_.channels.truth}) {
    // LCM subscribes by regular expression: anchor the literal channel name.
    std::string pattern;
    for (const char c : *ch) {
      if (std::string("\\^$.|?*+()[]{}").find(c) != std::string::npos) pattern += '\\';
      pattern += c;
    }
    subscriptions_.push_back(lcm_->subscribe(pattern, &LiveRenderer::OnMessage, this));
    // LCM drops, uncounted, what is queued beyond 30 messages per subscription by default. The
    // frames are counted here, not by LCM: small messages get the slices' 3 s of queue (TRACKS
    // at 10 Hz and poses at 100-200 Hz are kilobytes each). Whole scans and TRACK_DEBUG keep
    // LCM's 30 (3 s at 10 Hz; a 64-beam scan is 2.8 MB).
    if (ch == &job_.channels.slice || ch == &job_.channels.tracks || ch == &job_.channels.pose ||
        ch == &job_.channels.truth) {
      subscriptions_.back()->setQueueCapacity(lcm_util::kSliceQueueCapacity);
    }
  }
  render_thread_ = std::thread([this] { RenderLoop(); });
}

LiveRenderer::~LiveRenderer() {
  Finish();
  for (auto* s : subscriptions_) lcm_->unsubscribe(s);
}

void LiveRenderer::OnMessage(const lcm::ReceiveBuffer* rbuf, const std::string& channel) {
  // An LCM callback never lets an exception escape (STYLE): Route never throws, Offer only moves.
  last_message_ = std::chrono::steady_clock::now();
  router_.Route(channel, rbuf->data, rbuf->data_size);
  Offer(assembler_.TakeReady());
}

void LiveRenderer::Offer(std::vector<FrameInputs> frames) {
  if (failed_ || done_) return;  // the render thread has stopped taking frames
  for (auto& f : frames) {
    ++frames_ready_;
    slot_.Put(std::move(f));
  }
}

bool LiveRenderer::HandleOnce(int timeout_ms) {
  const int r = lcm_->handleTimeout(timeout_ms);
  if (r < 0) return false;
  if (assembler_.pending() > 0 && std::chrono::steady_clock::now() - last_message_ >= idle_flush_) {
    Offer(assembler_.Flush());
  }
  return true;
}

void LiveRenderer::RenderLoop() {
  SceneBuilder builder(job_.scene);
  cv::Mat image;
  while (auto f = slot_.Take()) {
    const double t = FrameTime(*f);
    if (t < job_.start_s || t > job_.end_s) {
      ++frames_skipped_;
      continue;
    }
    try {
      const Scene scene = builder.Build(*f);
      Render(scene, job_.render, MakeView(job_.render, scene), &image);
      sink_(scene, image);
    } catch (const std::exception& e) {
      {
        std::lock_guard<std::mutex> lock(error_mutex_);
        error_ = e.what();
      }
      failed_ = true;
      break;
    }
    ++frames_rendered_;
    if (job_.max_frames > 0 && frames_rendered_ >= job_.max_frames) {
      done_ = true;
      break;
    }
  }
}

void LiveRenderer::Finish() {
  if (finished_) return;
  finished_ = true;
  router_.Flush();
  Offer(assembler_.Flush());
  slot_.Close();
  if (render_thread_.joinable()) render_thread_.join();
  slot_.DropRemaining();
}

LiveStats LiveRenderer::stats() const {
  LiveStats s;
  s.frames_ready = frames_ready_;
  s.frames_rendered = frames_rendered_;
  s.frames_skipped = frames_skipped_;
  s.frames_dropped = slot_.dropped();
  s.tracks_late = assembler_.stats().late_tracks;
  if (const auto it = router_.received().find(job_.channels.tracks); it != router_.received().end()) {
    s.tracks_received = it->second;
  }
  s.decode_errors = router_.total_decode_errors();
  for (const auto& [channel, n] : router_.received()) s.messages += n;
  return s;
}

std::string LiveRenderer::error() const {
  std::lock_guard<std::mutex> lock(error_mutex_);
  return error_;
}

}  // namespace vtrack::viewer
