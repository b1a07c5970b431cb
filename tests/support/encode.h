// The bytes of an LCM message as its generated encoder writes them (header only: also for the
// fuzzers and the soak program, which do not link the test support library).
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace vtrack::testing {

template <class T>
std::vector<std::uint8_t> Encode(const T& m) {
  std::vector<std::uint8_t> b(static_cast<std::size_t>(m.getEncodedSize()));
  m.encode(b.data(), 0, static_cast<int>(b.size()));
  return b;
}

}  // namespace vtrack::testing
