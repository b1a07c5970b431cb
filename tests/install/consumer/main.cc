// Uses the installed message types (encode + checked decode) and the core library.
#include <cmath>
#include <cstdio>
#include <vector>

#include "lcmtypes/util/decode.h"
#include "base/angle.h"
#include "base/box.h"
#include "vtrack/track_list_t.hpp"

int main() {
  vtrack::track_list_t list{};
  list.utime = 123;
  list.mode = "mht";
  list.num_tracks = 1;
  list.tracks.resize(1);
  list.tracks[0].id = 42;
  list.tracks[0].theta = vtrack::WrapToPi(3.0 * vtrack::kPi / 2.0);
  std::vector<unsigned char> buf(list.getEncodedSize());
  list.encode(buf.data(), 0, static_cast<int>(buf.size()));
  vtrack::track_list_t back;
  if (vtrack::lcm_util::Decode(buf.data(), buf.size(), &back) != vtrack::lcm_util::DecodeError::kNone) {
    std::puts("decode failed");
    return 1;
  }
  const vtrack::OrientedBox box{{0.0, 0.0}, back.tracks[0].theta, 4.0, 2.0};
  const bool ok = back.tracks[0].id == 42 && std::abs(back.tracks[0].theta + vtrack::kPi / 2) < 1e-12 &&
                  box.Contains({0.0, -1.9}) && !box.Contains({0.0, 2.1});
  std::puts(ok ? "consumer OK" : "consumer WRONG");
  return ok ? 0 : 1;
}
