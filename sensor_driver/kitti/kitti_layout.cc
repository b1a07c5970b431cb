#include "sensor_driver/kitti/kitti_layout.h"

#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <random>
#include <sstream>
#include <vector>

#include "sensor_driver/kitti/kitti_io.h"

extern char** environ;

namespace vtrack::kitti {
namespace fs = std::filesystem;
namespace {

// "does not exist", or what is there instead: for the error of a path that must be a folder or a
// regular file.
std::string NotThere(const fs::path& p) {
  std::error_code ec;
  const fs::file_status st = fs::status(p, ec);
  if (!fs::exists(st)) return "does not exist";
  if (fs::is_directory(st)) return "is a directory, not a file";
  if (fs::is_regular_file(st)) return "is a file, not a directory";
  return "is not a regular file";
}


void Say(const MessageSink& sink, const std::string& msg) {
  if (sink) {
    sink(msg);
  } else {
    std::cerr << "[vtrack-kitti] " << msg << std::endl;
  }
}

// Runs argv (searched in PATH) to completion; returns its exit status (128 + signal if killed).
// stdout is captured into *out when out is not null; stderr goes to ours. Unpacking and hashing
// are delegated to tar/zstd/sha256sum (coreutils and the packages vtrack.sh installs) rather than
// linking a decompressor and a hash library for a step that runs once per archive.
int Run(const std::vector<std::string>& argv, std::string* out) {
  std::vector<char*> args;
  for (const auto& a : argv) args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);
  int pipe_fd[2] = {-1, -1};
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  if (out) {
    if (pipe(pipe_fd) != 0) throw KittiError(std::string("pipe failed: ") + std::strerror(errno));
    posix_spawn_file_actions_adddup2(&actions, pipe_fd[1], STDOUT_FILENO);
    posix_spawn_file_actions_addclose(&actions, pipe_fd[0]);
    posix_spawn_file_actions_addclose(&actions, pipe_fd[1]);
  }
  pid_t pid = -1;
  const int rc = posix_spawnp(&pid, args[0], &actions, nullptr, args.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  if (out) close(pipe_fd[1]);
  if (rc != 0) {
    if (out) close(pipe_fd[0]);
    throw KittiError("cannot run " + argv[0] + ": " + std::strerror(rc) + " (is it installed?)");
  }
  if (out) {
    char buf[4096];
    ssize_t got;
    while ((got = read(pipe_fd[0], buf, sizeof(buf))) != 0) {
      if (got < 0) {
        if (errno == EINTR) continue;
        break;
      }
      out->append(buf, static_cast<std::size_t>(got));
    }
    close(pipe_fd[0]);
  }
  int status = 0;
  while (waitpid(pid, &status, 0) < 0) {
    if (errno != EINTR) throw KittiError("waitpid for " + argv[0] + " failed: " + std::strerror(errno));
  }
  if (WIFEXITED(status)) return WEXITSTATUS(status);
  if (WIFSIGNALED(status)) return 128 + WTERMSIG(status);
  return -1;
}

bool IsHex64(const std::string& s) {
  if (s.size() != 64) return false;
  for (char c : s) {
    if (!std::isxdigit(static_cast<unsigned char>(c))) return false;
  }
  return true;
}

std::string Lower(std::string s) {
  for (auto& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

// The first whitespace-separated token of a sha256sum-style file, checked to be 64 hex digits.
std::string ReadExpectedSha(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw KittiError("cannot open checksum file " + path);
  std::string tok;
  in >> tok;
  if (!IsHex64(tok)) {
    throw KittiError(path + ":1: expected a SHA-256 (64 hex digits), got '" + tok + "'");
  }
  return Lower(tok);
}

std::string ComputeSha256(const std::string& path) {
  std::string out;
  const int rc = Run({"sha256sum", "-b", path}, &out);
  std::istringstream is(out);
  std::string tok;
  is >> tok;
  if (rc != 0 || !IsHex64(tok)) {
    throw KittiError("sha256sum of " + path + " failed (exit status " + std::to_string(rc) + ")");
  }
  return Lower(tok);
}

std::string RandomSuffix() {
  std::random_device rd;
  std::ostringstream os;
  os << ::getpid() << "-" << std::hex << rd();
  return os.str();
}

bool Exists(const fs::path& p) {
  std::error_code ec;
  return fs::exists(p, ec);
}

// A sequence's name as the layouts spell it: four decimal digits.
bool IsSequenceName(const std::string& s) {
  return s.size() == 4 && std::all_of(s.begin(), s.end(), [](char c) {
           return std::isdigit(static_cast<unsigned char>(c)) != 0;
         });
}

}  // namespace

std::string NormaliseSequence(const std::string& sequence) {
  if (sequence.empty() || sequence.size() > 4) {
    throw KittiError("bad sequence '" + sequence + "': expected 1 to 4 digits, e.g. 0000");
  }
  for (char c : sequence) {
    if (!std::isdigit(static_cast<unsigned char>(c))) {
      throw KittiError("bad sequence '" + sequence + "': expected 1 to 4 digits, e.g. 0000");
    }
  }
  return std::string(4 - sequence.size(), '0') + sequence;
}

std::vector<std::string> PointCloudSequences(const std::string& dir) {
  std::vector<std::string> out;
  if (dir.empty()) return out;  // not the current directory
  for (const fs::path& root : {fs::path(dir), fs::path(dir) / "training"}) {
    std::error_code ec;
    if (!fs::is_directory(root, ec)) continue;
    for (const auto& e : fs::directory_iterator(root, ec)) {
      const std::string name = e.path().filename().string();
      const std::string prefix = "velodyne_", suffix = ".tar.zst";
      if (name.size() == prefix.size() + 4 + suffix.size() && name.rfind(prefix, 0) == 0 &&
          name.compare(name.size() - suffix.size(), suffix.size(), suffix) == 0) {
        const std::string seq = name.substr(prefix.size(), 4);
        if (IsSequenceName(seq)) out.push_back(seq);
      }
    }
    if (fs::is_directory(root / "velodyne", ec)) {
      for (const auto& e : fs::directory_iterator(root / "velodyne", ec)) {
        const std::string seq = e.path().filename().string();
        if (IsSequenceName(seq) && e.is_directory(ec)) out.push_back(seq);
      }
    }
  }
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

std::string ResolveSequence(const std::string& dir, const std::string& requested) {
  if (!requested.empty()) return NormaliseSequence(requested);
  if (dir.empty()) throw KittiError("no KITTI directory given");
  if (!fs::is_directory(dir)) throw KittiError("KITTI directory " + dir + " " + NotThere(dir));
  std::vector<std::string> seqs = PointCloudSequences(dir);
  if (seqs.empty()) {
    // No point clouds (the boxes layout): the sequences with a calibration file.
    for (const fs::path& calib : {fs::path(dir) / "calib", fs::path(dir) / "training" / "calib"}) {
      std::error_code ec;
      if (!fs::is_directory(calib, ec)) continue;
      for (const auto& e : fs::directory_iterator(calib, ec)) {
        const std::string seq = e.path().stem().string();
        if (e.path().extension() == ".txt" && IsSequenceName(seq)) seqs.push_back(seq);
      }
    }
    std::sort(seqs.begin(), seqs.end());
    seqs.erase(std::unique(seqs.begin(), seqs.end()), seqs.end());
  }
  if (seqs.size() == 1) return seqs.front();
  if (seqs.empty()) {
    throw KittiError("no sequence in " + dir +
                     " (no velodyne/NNNN/, no velodyne_NNNN.tar.zst and no calib/NNNN.txt, nor "
                     "under training/): name the sequence (--sequence; vtrack-compare: "
                     "--kitti-sequence)");
  }
  std::string list;
  for (const auto& s : seqs) list += (list.empty() ? "" : ", ") + s;
  throw KittiError(dir + " holds several sequences (" + list +
                   "): name the one to read (--sequence; vtrack-compare: --kitti-sequence)");
}

std::string DefaultCacheDir() {
  if (const char* x = std::getenv("XDG_CACHE_HOME"); x && *x) return (fs::path(x) / "vtrack").string();
  if (const char* h = std::getenv("HOME"); h && *h) return (fs::path(h) / ".cache" / "vtrack").string();
  return (fs::temp_directory_path() / "vtrack-cache").string();
}

std::string UnpackVelodyneArchive(const std::string& archive, const std::string& sequence,
                                  const std::string& cache_dir_in, const MessageSink& sink) {
  const std::string seq = NormaliseSequence(sequence);
  const fs::path archive_path(archive);
  if (!fs::is_regular_file(archive_path)) throw KittiError("no archive " + archive);
  const std::string sha_file = archive + ".sha256";
  const bool have_sha = Exists(sha_file);
  // The cache key: the published checksum, or (without one) the archive's size and mtime.
  std::string key;
  std::string expected;
  if (have_sha) {
    expected = ReadExpectedSha(sha_file);
    key = expected.substr(0, 16);
  } else {
    std::ostringstream os;
    os << "size" << fs::file_size(archive_path) << "-mtime"
       << fs::last_write_time(archive_path).time_since_epoch().count();
    key = os.str();
  }
  // lexically_normal: "build/bin/../kitti_cache" must not create build/bin on the way.
  const fs::path cache_root =
      (fs::path(cache_dir_in.empty() ? DefaultCacheDir() : cache_dir_in) / "kitti").lexically_normal();
  std::string stem = archive_path.filename().string();
  const fs::path final_dir = cache_root / (stem + "-" + key);
  const fs::path velodyne_dir = final_dir / "velodyne" / seq;
  if (fs::is_directory(velodyne_dir)) return velodyne_dir.string();

  std::error_code ec;
  fs::create_directories(cache_root, ec);
  if (ec) throw KittiError("cannot create cache directory " + cache_root.string() + ": " + ec.message());
  if (have_sha) {
    Say(sink, "checking " + archive + " against " + sha_file);
    const std::string actual = ComputeSha256(archive);
    if (actual != expected) {
      throw KittiError("checksum mismatch for " + archive + ": SHA-256 is " + actual + ", " +
                       sha_file + " says " + expected);
    }
  }
  const fs::path tmp = cache_root / (stem + "-" + key + ".partial-" + RandomSuffix());
  fs::create_directories(tmp, ec);
  if (ec) throw KittiError("cannot create " + tmp.string() + ": " + ec.message());
  Say(sink, "unpacking " + archive + " (" + std::to_string(fs::file_size(archive_path) >> 20) +
                " MiB) into the cache " + final_dir.string() +
                " (once; choose the place with --cache-dir)");
  int rc = -1;
  try {
    rc = Run({"tar", "-x", "--zstd", "-f", archive, "-C", tmp.string()}, nullptr);
  } catch (...) {
    fs::remove_all(tmp, ec);
    throw;
  }
  if (rc != 0) {
    fs::remove_all(tmp, ec);
    throw KittiError("unpacking " + archive + " failed: tar exited with status " + std::to_string(rc) +
                     " (tar and zstd must be installed; is the archive complete?)");
  }
  if (!fs::is_directory(tmp / "velodyne" / seq)) {
    fs::remove_all(tmp, ec);
    throw KittiError("archive " + archive + " holds no velodyne/" + seq + "/ folder");
  }
  fs::rename(tmp, final_dir, ec);
  if (ec) {
    // Someone else finished first (parallel tests): use theirs.
    fs::remove_all(tmp, ec);
    if (!fs::is_directory(velodyne_dir)) {
      throw KittiError("cannot move the unpacked archive into " + final_dir.string());
    }
  }
  Say(sink, "unpacked into " + velodyne_dir.string());
  return velodyne_dir.string();
}

SequencePaths LocateSequence(const std::string& dir, const std::string& sequence,
                             const std::string& poses_file, const std::string& oxts_file,
                             const std::string& cache_dir, const MessageSink& sink) {
  const std::string seq = NormaliseSequence(sequence);
  if (dir.empty()) throw KittiError("no KITTI directory given");
  if (!fs::is_directory(dir)) throw KittiError("KITTI directory " + dir + " " + NotThere(dir));
  if (!poses_file.empty() && !oxts_file.empty()) {
    throw KittiError("give either a poses file or an OXTS file, not both (" + poses_file + ", " +
                     oxts_file + ")");
  }
  fs::path root(dir);
  auto has_sequence = [&](const fs::path& r) {
    return fs::is_directory(r / "velodyne" / seq) || Exists(r / ("velodyne_" + seq + ".tar.zst")) ||
           Exists(r / "ego_pose_orbslam3" / (seq + ".txt"));
  };
  if (!has_sequence(root) && has_sequence(root / "training")) root = root / "training";
  SequencePaths p;
  p.root = root.string();
  const fs::path archive = root / ("velodyne_" + seq + ".tar.zst");
  if (fs::is_directory(root / "velodyne" / seq)) {
    p.velodyne_dir = (root / "velodyne" / seq).string();
  } else if (Exists(archive)) {
    p.packed = true;
    p.velodyne_dir = UnpackVelodyneArchive(archive.string(), seq, cache_dir, sink);
  } else if (Exists(root / "ego_pose_orbslam3" / (seq + ".txt"))) {
    // The boxes layout: no point clouds.
  } else {
    throw KittiError("sequence " + seq + " not found in " + dir + ": no " +
                     (root / "velodyne" / seq).string() + "/ and no " + archive.string() +
                     (root == fs::path(dir) ? " (nor under training/)" : ""));
  }
  p.calib_file = (root / "calib" / (seq + ".txt")).string();
  if (!fs::is_regular_file(p.calib_file)) {
    throw KittiError("calibration file " + p.calib_file + " " + NotThere(p.calib_file));
  }
  const fs::path labels = root / "label_02" / (seq + ".txt");
  if (fs::is_regular_file(labels)) p.label_file = labels.string();
  const fs::path detections = root / "detections" / "pointrcnn_Car" / (seq + ".txt");
  if (fs::is_regular_file(detections)) p.detections_file = detections.string();

  if (!poses_file.empty()) {
    if (!fs::is_regular_file(poses_file)) throw KittiError("poses file " + poses_file + " " + NotThere(poses_file));
    p.poses_file = poses_file;
  } else if (!oxts_file.empty()) {
    if (!fs::is_regular_file(oxts_file)) throw KittiError("OXTS file " + oxts_file + " " + NotThere(oxts_file));
    p.oxts_file = oxts_file;
  } else {
    const fs::path oxts = root / "oxts" / (seq + ".txt");
    const fs::path icp = root / "ego_pose_estimated" / "poses_velo_icp.txt";
    const fs::path orbslam = root / "ego_pose_orbslam3" / (seq + ".txt");
    if (p.velodyne_dir.empty()) {
      p.camera_poses_file = orbslam.string();
    } else if (fs::is_regular_file(oxts)) {
      p.oxts_file = oxts.string();
    } else if (fs::is_regular_file(icp)) {
      p.poses_file = icp.string();
    } else {
      throw KittiError("no ego motion for sequence " + seq + ": neither " + oxts.string() + " nor " +
                       icp.string() + " exists; give a poses file (--poses) or an OXTS file (--oxts)");
    }
  }
  return p;
}

}  // namespace vtrack::kitti
