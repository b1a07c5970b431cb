// Checks of a parameter struct's Validate(std::string* error): for EXPECT_TRUE.
#pragma once

#include <gtest/gtest.h>

#include <initializer_list>
#include <string>

namespace vtrack::testing {

// The default parameters with one field set to value.
template <typename Params, typename T, typename V>
Params With(T Params::*field, V value) {
  Params p;
  p.*field = value;
  return p;
}

// p validates (the failure shows Validate's message).
template <typename Params>
::testing::AssertionResult Accepted(const Params& p) {
  std::string error;
  if (p.Validate(&error)) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << "refused: " << error;
}

// p does not validate, and Validate's message holds every one of pieces (e.g. the key and the
// value it was given).
template <typename Params>
::testing::AssertionResult RefusedSaying(const Params& p,
                                         std::initializer_list<const char*> pieces) {
  std::string error;
  if (p.Validate(&error)) return ::testing::AssertionFailure() << "accepted";
  for (const char* piece : pieces) {
    if (error.find(piece) == std::string::npos) {
      return ::testing::AssertionFailure() << "the message does not say '" << piece << "': "
                                           << error;
    }
  }
  return ::testing::AssertionSuccess();
}

}  // namespace vtrack::testing
