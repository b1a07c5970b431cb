// tracks-canonical: writes the TRACKS messages of an LCM log to stdout as canonical bytes, with
// the one field that depends on the machine (track_list_t.latency_us, a wall-clock measurement)
// set to 0. Two runs of the tracker that decide the same things give the same bytes; piped into
// sha256sum this is the digest that scripts/check-tracks-digest compares against the recorded
// one (tests/behaviour/tracks.sha256).
#include <cstdio>
#include <cstring>
#include <exception>
#include <string>
#include <vector>

#include "lcmtypes/util/decode.h"
#include "lcmtypes/util/log_reader.h"
#include "vtrack/track_list_t.hpp"

int main(int argc, char** argv) {
  if (argc != 3 || std::strcmp(argv[1], "--help") == 0 || std::strcmp(argv[1], "-h") == 0) {
    std::fprintf(argc == 2 ? stdout : stderr,
                 "usage: tracks-canonical LOG CHANNEL\n"
                 "Writes every CHANNEL event of LOG (vtrack.track_list_t) re-encoded with\n"
                 "latency_us = 0 to stdout, each preceded by its 4-byte big-endian length.\n");
    return argc == 2 ? 0 : 2;
  }
  try {
    vtrack::lcm_util::LogReader reader(argv[1]);
    const std::string channel = argv[2];
    std::vector<unsigned char> buf;
    long count = 0;
    while (const lcm::LogEvent* e = reader.Next()) {
      if (e->channel != channel) continue;
      vtrack::track_list_t msg;
      std::string why;
      const auto err = vtrack::lcm_util::Decode(e->data, static_cast<std::size_t>(e->datalen), &msg, &why);
      if (err != vtrack::lcm_util::DecodeError::kNone) {
        std::fprintf(stderr, "tracks-canonical: event %lld on %s does not decode: %s %s\n",
                     static_cast<long long>(e->eventnum), channel.c_str(),
                     vtrack::lcm_util::DecodeErrorName(err), why.c_str());
        return 1;
      }
      msg.latency_us = 0;
      const int n = msg.getEncodedSize();
      buf.resize(static_cast<std::size_t>(n) + 4);
      buf[0] = static_cast<unsigned char>(n >> 24);
      buf[1] = static_cast<unsigned char>(n >> 16);
      buf[2] = static_cast<unsigned char>(n >> 8);
      buf[3] = static_cast<unsigned char>(n);
      msg.encode(buf.data() + 4, 0, n);
      std::fwrite(buf.data(), 1, buf.size(), stdout);
      ++count;
    }
    if (count == 0) {
      std::fprintf(stderr, "tracks-canonical: no %s event in %s\n", channel.c_str(), argv[1]);
      return 1;
    }
    std::fprintf(stderr, "tracks-canonical: %ld %s messages\n", count, channel.c_str());
  } catch (const std::exception& ex) {
    std::fprintf(stderr, "tracks-canonical: %s\n", ex.what());
    return 1;
  }
  return 0;
}
