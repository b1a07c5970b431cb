// The one source of vtrack_test_pch (tests/CMakeLists.txt): the target that builds the
// precompiled header the test sources share. It holds no tests.
#include <gtest/gtest.h>
