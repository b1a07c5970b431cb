// vtrack-render: draws what the tracker did, top-down in the style of the paper's Figure 4, into
// an MP4 video and PNG snapshots. Offline from LCM logs (--input, as fast as possible) or live
// from the bus. See viewer/README.md.
#include <boost/program_options.hpp>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "lcmtypes/util/command_line.h"
#include "lcmtypes/util/process.h"
#include "lcmtypes/util/text.h"
#include "viewer/frame_output.h"
#include "viewer/live_render.h"
#include "viewer/offline_render.h"
#include "viewer/render_job.h"

namespace po = boost::program_options;
using vtrack::viewer::AssemblerParams;
using vtrack::viewer::RenderParams;

namespace {

constexpr int kExitBadOptions = 2;

struct UsageError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

std::vector<double> ParseNumbers(const std::string& option, const std::string& text,
                                 char separator, std::size_t expected = 0) {
  std::string bad;
  const std::optional<std::vector<double>> out =
      vtrack::lcm_util::ParseNumberList(text, separator, /*finite_only=*/true, &bad);
  if (!out) throw UsageError("--" + option + " '" + text + "': '" + bad + "' is not a number");
  if (out->empty() || (expected > 0 && out->size() != expected)) {
    throw UsageError("--" + option + " '" + text + "': expected " +
                     (expected > 0 ? std::to_string(expected) : std::string("one or more")) +
                     " numbers separated by '" + separator + "'");
  }
  return *out;
}

std::int64_t Microseconds(double seconds) {
  return static_cast<std::int64_t>(std::llround(seconds * 1e6));
}

}  // namespace

int main(int argc, char** argv) {
  vtrack::viewer::RenderJob job;
  vtrack::viewer::OutputParams output;
  std::vector<std::string> inputs;
  std::string lcm_url, size = "1280x960", window, png_at, frame_on = "auto", ground = "grid",
              ego_size = "4.5,1.8";
  double duration_s = 0.0, lag_s = 0.3, end_s = -1.0;
  bool quiet = false;

  po::options_description general("General");
  general.add_options()
      ("help,h", "show this help")
      ("input,i", po::value(&inputs)->multitoken()->composing(),
       "LCM log file(s) to render offline, merged by event time (e.g. the simulator's log and "
       "the tracker's tracks.lcm); without --input, render live from the bus")
      ("lcm-url", po::value(&lcm_url),
       "live: LCM URL (default $LCM_DEFAULT_URL or LCM's default); recv_buf_size=4194304 is "
       "added to a udpm:// URL that sets none")
      ("duration", po::value(&duration_s)->default_value(0.0),
       "live: stop after this many seconds (0 = until Ctrl-C)")
      ("max-frames", po::value(&job.max_frames)->default_value(0),
       "stop after this many rendered frames (0 = no limit)")
      ("start", po::value(&job.start_s)->default_value(0.0),
       "render only frames at least this many seconds after the start of the run")
      ("end", po::value(&end_s)->default_value(-1.0),
       "and at most this many seconds after it (negative = to the end)")
      ("quiet,q", po::bool_switch(&quiet), "no progress bar or status lines");

  po::options_description out("Output");
  out.add_options()
      ("video", po::value(&output.video_path), "MP4 video to write (FFmpeg, mp4v)")
      ("fps", po::value(&output.fps)->default_value(0.0),
       "video frame rate (0 = the scan rate, from the frames' times)")
      ("png-dir", po::value(&output.png_dir), "directory for PNG snapshots frame_NNNNNN.png")
      ("png-every", po::value(&output.png_every),
       "a PNG every N frames (default 25 with --png-dir and no --png-at; 0 = off)")
      ("png-at", po::value(&png_at),
       "PNGs at these times, seconds since the start of the run, comma separated (e.g. 2.5,10)");

  po::options_description view("View");
  view.add_options()
      ("size", po::value(&size)->default_value(size), "frame size WxH in pixels (even numbers)")
      ("zoom", po::value(&job.render.zoom)->default_value(job.render.zoom),
       "scale in pixels per metre, following the ego vehicle")
      ("window", po::value(&window),
       "fixed world window XMIN,YMIN,XMAX,YMAX [m] instead of following the ego vehicle")
      ("follow-track", po::value(&job.render.follow_track_id),
       "centre on this track id instead of the ego vehicle (the ego while the track is absent)")
      ("hypotheses", po::bool_switch(&job.render.show_hypotheses),
       "draw every hypothesis of each mover (paper Fig. 6 b-d)")
      ("hide-clutter", po::bool_switch(), "do not draw tracks classed as clutter (\"other\")")
      ("hide-truth", po::bool_switch(), "do not draw ground truth")
      ("no-legend", po::bool_switch(), "no colour legend")
      ("no-grid", po::bool_switch(), "no metric grid")
      ("ellipse-sigma", po::value(&job.render.ellipse_sigma)->default_value(job.render.ellipse_sigma),
       "covariance ellipses at this many standard deviations")
      ("point-size", po::value(&job.render.point_size)->default_value(job.render.point_size),
       "side of a LADAR dot in pixels")
      ("trail", po::value(&job.assembler.trail_s)->default_value(job.assembler.trail_s),
       "seconds of recent trajectory drawn (tracks, ego, truth)")
      ("truth-ahead", po::value(&job.assembler.truth_ahead_s)->default_value(job.assembler.truth_ahead_s),
       "offline: seconds of true trajectory drawn ahead of each frame")
      ("ground", po::value(&ground)->default_value(ground),
       "ground removal for 3-D scans, as in the tracker: none | band | grid")
      ("ego-size", po::value(&ego_size)->default_value(ego_size), "ego outline LENGTH,WIDTH [m]")
      ("ego-ahead", po::value(&job.scene.ego_center_ahead)->default_value(0.0),
       "ego outline centre ahead of the pose origin [m]");

  po::options_description frames("Frames and channels");
  frames.add_options()
      ("frame-on", po::value(&frame_on)->default_value(frame_on),
       "what makes a frame: tracks (one per TRACKS message), scans (one per LADAR_SCAN), or "
       "auto (offline: tracks if the logs have any, else scans; live: tracks, and scans while "
       "no tracker publishes)")
      ("lag", po::value(&lag_s)->default_value(lag_s, "0.3"),
       "seconds of data time a frame waits for its debug message, poses and truth")
      ("scan-channel", po::value(&job.channels.scan)->default_value(job.channels.scan),
       "LADAR scans (ladar_scan_t)")
      ("slice-channel", po::value(&job.channels.slice)->default_value(job.channels.slice),
       "LADAR sweeps sent as slices (ladar_slice_t), joined into scans")
      ("pose-channel", po::value(&job.channels.pose)->default_value(job.channels.pose),
       "ego pose (pose_t)")
      ("tracks-channel", po::value(&job.channels.tracks)->default_value(job.channels.tracks),
       "tracker output (track_list_t)")
      ("debug-channel", po::value(&job.channels.debug)->default_value(job.channels.debug),
       "tracker diagnostics (track_debug_t)")
      ("truth-channel", po::value(&job.channels.truth)->default_value(job.channels.truth),
       "ground truth (object_list_t)");

  const char* usage =
      "vtrack-render: top-down frames of LADAR scans, tracks and ground truth in the style of the\n"
      "paper's Figure 4, written to an MP4 video and PNG snapshots (viewer/README.md).\n\n"
      "  offline: vtrack-render --input run.lcm --input tracks.lcm --video out.mp4 --png-dir png/\n"
      "  live:    vtrack-render --video live.mp4 --png-dir png/    (Ctrl-C to stop)";
  po::options_description all;
  all.add(general).add(out).add(view).add(frames);
  po::positional_options_description positional;
  positional.add("input", -1);

  po::variables_map vm;
  try {
    if (!vtrack::lcm_util::StoreCommandLine(
            po::command_line_parser(argc, argv).options(all).positional(positional).run(), all, &vm,
            usage)) {
      return 0;
    }

    // View.
    {
      const auto wh = ParseNumbers("size", size, 'x', 2);
      job.render.width = static_cast<int>(wh[0]);
      job.render.height = static_cast<int>(wh[1]);
      if (wh[0] != job.render.width || wh[1] != job.render.height) {
        throw UsageError("--size '" + size + "': width and height must be whole pixels");
      }
    }
    if (vm.count("follow-track")) {
      if (!window.empty()) throw UsageError("--window and --follow-track both given: choose one");
      job.render.follow = RenderParams::Follow::kTrack;
    }
    if (!window.empty()) {
      if (!vm["zoom"].defaulted()) {
        throw UsageError("--window and --zoom both given: the window sets the scale");
      }
      const auto w = ParseNumbers("window", window, ',', 4);
      if (!(w[2] > w[0]) || !(w[3] > w[1])) {
        throw UsageError("--window '" + window + "': needs XMIN < XMAX and YMIN < YMAX");
      }
      job.render.follow = RenderParams::Follow::kWindow;
      job.render.window = Eigen::AlignedBox2d(Eigen::Vector2d(w[0], w[1]), Eigen::Vector2d(w[2], w[3]));
    }
    job.render.show_clutter = !vm["hide-clutter"].as<bool>();
    job.render.show_truth = !vm["hide-truth"].as<bool>();
    job.render.show_legend = !vm["no-legend"].as<bool>();
    job.render.show_grid = !vm["no-grid"].as<bool>();
    if (!vtrack::FromName(ground, &job.scene.preprocess.ground)) {
      throw UsageError("--ground '" + ground + "': must be none, band or grid");
    }
    {
      const auto lw = ParseNumbers("ego-size", ego_size, ',', 2);
      job.scene.ego_length = lw[0];
      job.scene.ego_width = lw[1];
    }

    // Frames.
    if (frame_on == "auto") {
      job.assembler.trigger = AssemblerParams::Trigger::kAuto;
    } else if (frame_on == "tracks") {
      job.assembler.trigger = AssemblerParams::Trigger::kTracks;
    } else if (frame_on == "scans") {
      job.assembler.trigger = AssemblerParams::Trigger::kScans;
    } else {
      throw UsageError("--frame-on '" + frame_on + "': must be auto, tracks or scans");
    }
    if (!(lag_s >= 0.0) || lag_s > 10.0) {
      throw UsageError("--lag " + std::to_string(lag_s) + ": must be in [0, 10] s");
    }
    job.assembler.lag_us = Microseconds(lag_s);
    if (end_s >= 0.0) job.end_s = end_s;
    if (!(duration_s >= 0.0)) throw UsageError("--duration must be >= 0 s");

    // Output.
    if (!png_at.empty()) output.png_at_s = ParseNumbers("png-at", png_at, ',');
    if (!output.png_dir.empty() && !vm.count("png-every") && output.png_at_s.empty()) {
      output.png_every = 25;
    }
    if (output.video_path.empty() && output.png_dir.empty()) {
      throw UsageError("nothing to write: give --video FILE.mp4 and/or --png-dir DIR");
    }
    {
      std::vector<vtrack::lcm_util::PathArgument> in;
      for (const std::string& i : inputs) in.push_back({"--input", i});
      vtrack::lcm_util::RefuseOverwritingInputs(in, {{"--video", output.video_path}});
    }
    if (!inputs.empty() && vm.count("lcm-url")) {
      throw UsageError("--lcm-url is for live rendering; with --input the logs are read directly");
    }
    for (const std::string& err : {job.FirstProblem(), output.FirstProblem()}) {
      if (!err.empty()) throw UsageError(err);
    }
  } catch (const po::error& e) {
    std::cerr << "vtrack-render: " << e.what() << " (see --help)\n";
    return kExitBadOptions;
  } catch (const UsageError& e) {
    std::cerr << "vtrack-render: " << e.what() << " (see --help)\n";
    return kExitBadOptions;
  }

  vtrack::lcm_util::InstallStopHandlers();
  try {
    vtrack::viewer::FrameOutput sink(output);
    if (!inputs.empty()) {
      const auto st = vtrack::viewer::RenderLogs(inputs, job, &sink, !quiet);
      sink.Close();
      for (const auto& w : st.warnings) std::cerr << "vtrack-render: warning: " << w << "\n";
      std::fprintf(stderr,
                   "vtrack-render: %lld frames (one per %s message; %lld in the logs, %lld "
                   "outside --start/--end, %lld too late to place) in %.1f s; %lld decode "
                   "errors\n",
                   static_cast<long long>(st.frames_rendered),
                   st.trigger == AssemblerParams::Trigger::kTracks ? job.channels.tracks.c_str()
                                                                   : job.channels.scan.c_str(),
                   static_cast<long long>(st.expected_frames),
                   static_cast<long long>(st.frames_skipped),
                   static_cast<long long>(st.late_dropped), st.wall_s,
                   static_cast<long long>(st.decode_errors));
      if (!st.warnings.empty()) return 3;  // rendered what was whole; the input was damaged
    } else {
      const std::string url = vtrack::viewer::WithReceiveBuffer(lcm_url);
      auto lcm = vtrack::lcm_util::OpenLcm(url);
      vtrack::viewer::LiveRenderer live(
          lcm.get(), job, [&](const vtrack::viewer::Scene& scene, const cv::Mat& image) {
            sink.Write(image, scene.utime, scene.time_s);
          });
      if (!quiet) std::fprintf(stderr, "vtrack-render: rendering live from %s\n", url.c_str());
      const auto start = std::chrono::steady_clock::now();
      auto last_status = start;
      bool lcm_ok = true;
      while (!vtrack::lcm_util::StopRequested() && !live.failed() && !live.done()) {
        const auto now = std::chrono::steady_clock::now();
        if (duration_s > 0.0 && now - start >= std::chrono::duration<double>(duration_s)) break;
        if (!live.HandleOnce(100)) {
          // A stop signal interrupts LCM's wait (EINTR): that is the normal end, not an error.
          lcm_ok = vtrack::lcm_util::StopRequested();
          break;
        }
        if (!quiet && now - last_status >= std::chrono::seconds(10)) {
          const auto s = live.stats();
          std::fprintf(stderr, "vtrack-render: %lld frames rendered, %lld dropped\n",
                       static_cast<long long>(s.frames_rendered),
                       static_cast<long long>(s.frames_dropped));
          last_status = now;
        }
      }
      live.Finish();
      sink.Close();
      const auto s = live.stats();
      std::fprintf(stderr,
                   "vtrack-render: %lld frames rendered, %lld dropped (renderer behind), %lld "
                   "outside --start/--end; %lld %s messages received, %lld of them too late to "
                   "draw in order; %lld decode errors\n",
                   static_cast<long long>(s.frames_rendered),
                   static_cast<long long>(s.frames_dropped),
                   static_cast<long long>(s.frames_skipped),
                   static_cast<long long>(s.tracks_received), job.channels.tracks.c_str(),
                   static_cast<long long>(s.tracks_late),
                   static_cast<long long>(s.decode_errors));
      if (live.failed()) throw std::runtime_error(live.error());
      if (!lcm_ok) throw std::runtime_error("LCM reported an error while handling messages");
    }
    if (!output.video_path.empty() && sink.video_frames() > 0) {
      std::fprintf(stderr, "vtrack-render: video %s: %lld frames at %.2f fps\n",
                   output.video_path.c_str(), static_cast<long long>(sink.video_frames()),
                   sink.fps());
    }
    if (!output.png_dir.empty()) {
      std::fprintf(stderr, "vtrack-render: %zu PNG snapshots in %s\n", sink.png_paths().size(),
                   output.png_dir.c_str());
    }
    if (sink.video_frames() == 0 && sink.png_paths().empty()) {
      // From logs, not a success: the user asked for images of them and has none (a window of
      // time past their end, none at a --png-at time). Live, a display stopped before anything
      // came on the bus has drawn nothing either, which is said but is no failure.
      const std::string what =
          output.video_path.empty() ? "" : " (no video " + output.video_path + ")";
      if (!inputs.empty()) {
        std::fprintf(stderr, "vtrack-render: nothing written%s: no frame within --start/--end%s\n",
                     what.c_str(), output.png_at_s.empty() ? "" : ", or none at a --png-at time");
        return 1;
      }
      std::fprintf(stderr, "vtrack-render: nothing written%s: no frame came on the bus\n", what.c_str());
    }
  } catch (const std::exception& e) {
    std::cerr << "vtrack-render: error: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
