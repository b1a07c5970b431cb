// libFuzzer harness for the message decoders. Compiled once per message type with
// -DVTRACK_FUZZ_TYPE=<type>. The input is the message body: the harness prepends the type's
// fingerprint so the fuzzer explores the body instead of guessing 8 fingerprint bytes, and also
// decodes the raw input to exercise the fingerprint path.
//
// Oracle: Decode<T> never crashes, never allocates beyond what the buffer can carry (the
// sanitizers and libFuzzer's -rss_limit_mb / -malloc_limit_mb catch that), and whatever it
// accepts re-encodes to exactly the bytes it was decoded from.
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <vector>

#include "lcmtypes/util/decode.h"
#include "vtrack/detection_list_t.hpp"
#include "vtrack/detection_t.hpp"
#include "vtrack/ladar_scan_t.hpp"
#include "vtrack/ladar_slice_t.hpp"
#include "vtrack/object_list_t.hpp"
#include "vtrack/pose_t.hpp"
#include "vtrack/track_debug_t.hpp"
#include "vtrack/track_list_t.hpp"
#include "vtrack/tracker_status_t.hpp"

#ifndef VTRACK_FUZZ_TYPE
#error "define VTRACK_FUZZ_TYPE"
#endif

namespace {

using Msg = vtrack::VTRACK_FUZZ_TYPE;

void Check(const std::uint8_t* data, std::size_t size) {
  Msg msg;
  if (vtrack::lcm_util::Decode(data, size, &msg) != vtrack::lcm_util::DecodeError::kNone) return;
  const int n = msg.getEncodedSize();
  std::vector<std::uint8_t> again(static_cast<std::size_t>(n));
  if (msg.encode(again.data(), 0, n) != n || again.size() != size ||
      std::memcmp(again.data(), data, size) != 0) {
    std::abort();  // accepted a message that does not re-encode to its own bytes
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  Check(data, size);
  std::vector<std::uint8_t> with_hash(8 + size);
  const std::int64_t h = Msg::getHash();
  for (int i = 0; i < 8; ++i) with_hash[i] = static_cast<std::uint8_t>(static_cast<std::uint64_t>(h) >> (56 - 8 * i));
  if (size) std::memcpy(with_hash.data() + 8, data, size);
  Check(with_hash.data(), with_hash.size());
  return 0;
}
