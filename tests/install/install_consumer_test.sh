#!/usr/bin/env bash
# cmake --install the build into a temporary prefix, then build and run a separate project that
# finds it with find_package(vtrack) and links vtrack::core and vtrack::msgs.
#   usage: install_consumer_test.sh BUILD_DIR CONSUMER_SOURCE_DIR
set -euo pipefail
build=$1; consumer=$2
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cmake --install "$build" --prefix "$work/prefix" >"$work/install.log" 2>&1 || { cat "$work/install.log"; exit 1; }
for f in lib/cmake/vtrack/vtrackConfig.cmake include/vtrack/track_t.hpp share/java/vtrack_lcmtypes.jar \
         include/vtrack/base/box.h bin/vtrack-netns; do
  [ -e "$work/prefix/$f" ] || { echo "FAIL: not installed: $f"; exit 1; }
done
# A sanitized build installs instrumented static libraries: a consumer links them with the same
# compiler (its sanitizer runtime) and the same -fsanitize link flags.
extra=()
cache_get() { sed -n "s/^$1:[A-Z]*=//p" "$build/CMakeCache.txt"; }
if [ "$(cache_get VTRACK_SANITIZE)" = ON ]; then
  extra=(-DCMAKE_CXX_COMPILER="$(cache_get CMAKE_CXX_COMPILER)"
         -DCMAKE_EXE_LINKER_FLAGS=-fsanitize=address,undefined)
fi
cmake -S "$consumer" -B "$work/build" -DCMAKE_PREFIX_PATH="$work/prefix" "${extra[@]}" >"$work/configure.log" 2>&1 \
  || { cat "$work/configure.log"; exit 1; }
cmake --build "$work/build" -j2 >"$work/build.log" 2>&1 || { cat "$work/build.log"; exit 1; }
"$work/build/consumer"
