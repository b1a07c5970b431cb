// The input format of the tracker fuzzer (tracker_fuzzer.cc): a byte string read as a small
// program that drives vtrack-tracker's node. Every byte string is a valid program (missing bytes
// read as zero), so libFuzzer's mutations always reach the tracker. Shared with the seed writer
// (make_seed_corpus.cc) so that the seeds are meaningful programs.
//
//   header:  mode (byte % 4: mht, ism, vasm, cv), rings (byte: 1 or a 3-D cloud of 16 rings),
//            number of objects (byte % 5), then per object 7 bytes:
//            x, y (int8 x 0.5 m, world), yaw (byte x 2 pi / 256), length, width
//            (1 + byte / 32 m), speed (int8 x 0.25 m/s), yaw rate (int8 x 0.01 rad/s)
//   then ops until the input ends (at most kMaxOps):
//     kOpPose      dt (int16 us x 100, may be <= 0), ego speed (int8 x 0.25 m/s), yaw rate
//                  (int8 x 0.01 rad/s), flags (kPose*)
//     kOpScan      dt (int16 us x 100), seq step (int8), sweep (byte x 1 ms), points per
//                  object (byte % 64), flags (kScan*), corrupt index (byte)
//     kOpRaw       channel (byte & 1: scan / pose), prepend fingerprint (byte & 2), length (byte),
//                  then that many raw bytes as the message body
//     kOpInflate   a scan whose npoints field is overwritten by (int32), encoded and sent
//     kOpFlush     Flush() and a TRACKER_STATUS
#pragma once

#include <cstdint>

namespace vtrack::fuzz {

enum Op : std::uint8_t { kOpPose = 0, kOpScan = 1, kOpRaw = 2, kOpInflate = 3, kOpFlush = 4, kNumOps = 5 };

// kOpPose flags.
enum PoseFlag : std::uint8_t {
  kPoseNaN = 1,          // a NaN position
  kPoseBadQuat = 2,      // a quaternion far from unit length
  kPoseFar = 4,          // the ego 1e9 m from the origin (finite, extreme)
  kPoseRepeat = 8,       // the same time as the previous pose
  kPoseJumpBack = 16,    // 10 s back in time (a looped log)
};

// kOpScan flags.
enum ScanFlag : std::uint8_t {
  kScanNaN = 1,          // the corrupt-index return gets NaN
  kScanInf = 2,          // ... +Inf
  kScanBadTime = 4,      // ... dt_us outside the sweep
  kScanCollapse = 8,     // all returns of each object on one point (degenerate fits)
  kScanLine = 16,        // all returns of each object on one straight segment
  kScanHuge = 32,        // append returns beyond the fuzzer's max_points
  kScanDuplicate = 64,   // every return sent twice
  kScanFarPoints = 128,  // returns 1e30 m away
};

constexpr int kMaxOps = 64;
constexpr int kMaxObjects = 4;
constexpr std::int64_t kStartUtime = 1'700'000'000'000'000;  // [us]

}  // namespace vtrack::fuzz
