#!/usr/bin/env bash
# vtrack: the one entry point. Installs what is missing (Debian 12 packages), builds, and runs.
#
#   ./vtrack.sh demo [DEMO OPTIONS]   the main job (see ./vtrack.sh demo --help)
#   ./vtrack.sh test [CTEST ARGS]     every test (CI), then again under ASan+UBSan + short fuzzing
#                                     (VTRACK_TEST_SANITIZERS=0: without that half)
#   ./vtrack.sh bench [--json F]      the benchmarks: one table + bench-results.json
#   ./vtrack.sh fuzz [SECONDS]        build the libFuzzer harnesses (clang) and run each SECONDS (60)
#   ./vtrack.sh build                 set up and build only
#   ./vtrack.sh deps                  install the Debian packages only
#
# Environment: VTRACK_BUILD_DIR (default ./build), VTRACK_JOBS (default 2).
set -euo pipefail

here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
build_dir=${VTRACK_BUILD_DIR:-$here/build}
jobs=${VTRACK_JOBS:-2}

# Debian 12 packages, by purpose. Each command installs only what it needs and is missing.
pkgs_build=(g++ make cmake pkg-config lld
  liblcm-dev liblcm-bin liblcm-java
  libeigen3-dev libyaml-cpp-dev libboost-program-options-dev
  libopencv-core-dev libopencv-imgproc-dev libopencv-imgcodecs-dev libopencv-videoio-dev
  libgtest-dev libbenchmark-dev default-jdk-headless)
pkgs_run=(iproute2 procps zstd tar)
pkgs_test=(xvfb xauth default-jre libjchart2d-java nftables python3 python3-yaml)
pkgs_bench=(jq)
pkgs_bench_optional=(libpcl-dev)  # the peer of pcl_bench; without it that comparison is skipped
pkgs_fuzz=(clang libclang-rt-14-dev)

usage() { sed -n '2,12p' "$0" | sed 's/^# \{0,1\}//'; }

log() { printf '\033[1m[vtrack]\033[0m %s\n' "$*" >&2; }

install_packages() {
  local missing=() p
  for p in "$@"; do
    if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q 'install ok installed'; then
      missing+=("$p")
    fi
  done
  [ ${#missing[@]} -eq 0 ] && return 0
  local sudo=()
  if [ "$(id -u)" != 0 ]; then
    if command -v sudo >/dev/null 2>&1 && sudo -n true 2>/dev/null; then
      sudo=(sudo -n)
    else
      log "missing Debian packages: ${missing[*]}"
      log "not root and no password-less sudo: install them with"
      log "  sudo apt-get install ${missing[*]}"
      exit 1
    fi
  fi
  log "installing Debian packages: ${missing[*]}"
  export DEBIAN_FRONTEND=noninteractive
  "${sudo[@]}" apt-get update -qq
  "${sudo[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
}

configure_and_build() {
  local type=${1:-Release}; shift || true
  log "building ($type) in $build_dir with $jobs jobs"
  cmake -S "$here" -B "$build_dir" -DCMAKE_BUILD_TYPE="$type" "$@" >/dev/null
  cmake --build "$build_dir" -j "$jobs"
}

# The whole suite again under AddressSanitizer + UndefinedBehaviorSanitizer, built with clang
# (whose UBSan also checks float-to-int overflow), -O1 with line tables and asserts on (the test
# sources themselves at -O0: half the compile time, tests/CMakeLists.txt), no
# benchmarks (nothing they test that the tests do not), in its own tree; then a short smoke run
# of every libFuzzer harness from the same tree (coverage from the harness files only: compiling
# the libraries with coverage would cost more than the run; ./vtrack.sh fuzz has it all).
# VTRACK_TEST_SANITIZERS=0 leaves it out.
#
# Time: the sanitizer tree is built in the background at the lowest CPU priority (nice 19) from
# the start, so it takes the cycles that the Release build and the Release tests leave (the tests
# mostly wait on real time); Linux's scheduler gives a nice-19 job about 1.5 % of a core against
# a nice-0 one, so the live tests' timing is undisturbed. Its own tests start when both are done;
# the fuzz smoke run goes alongside them, niced the same way. A test that feeds a live process
# in real time slows its feed in this tree (tests/support/test_env.h LiveRate()).
sanitizer_dir=${VTRACK_SANITIZE_BUILD_DIR:-$build_dir-asan}
background_pids=()
stop_background() {
  local pid
  for pid in "${background_pids[@]}"; do kill -- "-$pid" 2>/dev/null || true; done
}

start_sanitizer_build() {
  log "building with ASan + UBSan (clang) in $sanitizer_dir, at low priority in the background"
  mkdir -p "$sanitizer_dir"
  # setsid: its own process group, so that stop_background ends the compilers too. A new session
  # is also a new scheduler autogroup (Linux's CONFIG_SCHED_AUTOGROUP), and autogroups share the
  # CPU equally whatever their tasks' nice: so the autogroup itself is niced (measured: without
  # that the "nice 19" build took half the CPU from the Release build; with it ~2 %).
  setsid nice -n 19 bash -c '
    echo 19 > /proc/self/autogroup 2>/dev/null || true
    CC=clang CXX=clang++ cmake -S "$1" -B "$2" -DCMAKE_BUILD_TYPE=RelWithDebInfo \
      -DCMAKE_C_FLAGS_RELWITHDEBINFO="-O1 -gline-tables-only" \
      -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -gline-tables-only" \
      -DVTRACK_SANITIZE=ON -DVTRACK_BUILD_FUZZERS=ON -DVTRACK_FUZZ_COVERAGE=OFF \
      -DVTRACK_BUILD_BENCHMARKS=OFF -DVTRACK_TEST_COMPILE_OPTIONS=-O0 && cmake --build "$2" -j "$3"' \
    _ "$here" "$sanitizer_dir" "$jobs" >"$sanitizer_dir/build.log" 2>&1 &
  sanitizer_build_pid=$!
  background_pids+=("$sanitizer_build_pid")
}

sanitizer_tests() {
  local start fuzz_pid rc=0
  log "waiting for the sanitizer build (log: $sanitizer_dir/build.log)"
  if ! wait "$sanitizer_build_pid"; then
    tail -n 40 "$sanitizer_dir/build.log" >&2
    log "the sanitizer build failed (whole log: $sanitizer_dir/build.log)"
    return 1
  fi
  start=$(date +%s)
  log "fuzzing every harness for ${VTRACK_FUZZ_SECONDS:-10} s (low priority, beside the tests)"
  setsid nice -n 19 bash -c 'echo 19 > /proc/self/autogroup 2>/dev/null || true
    VTRACK_FUZZ_BUILD_DIR="$1" VTRACK_FUZZ_PREBUILT=1 exec "$2/scripts/fuzz.sh" "$2" "$3"' \
    _ "$sanitizer_dir" "$here" "${VTRACK_FUZZ_SECONDS:-10}" >"$sanitizer_dir/fuzz.log" 2>&1 &
  fuzz_pid=$!
  background_pids+=("$fuzz_pid")
  log "running every test under ASan + UBSan"
  ctest --test-dir "$sanitizer_dir" --output-on-failure -j "$jobs" "$@" || rc=$?
  if ! wait "$fuzz_pid"; then
    log "fuzz smoke run failed:"; cat "$sanitizer_dir/fuzz.log" >&2; rc=1
  else
    cat "$sanitizer_dir/fuzz.log" >&2
  fi
  [ $rc -eq 0 ] || return $rc
  log "sanitizer tests and fuzz smoke run passed in $(( $(date +%s) - start )) s"
}

cmd=${1:-help}
shift || true
case "$cmd" in
  -h|--help|help)
    usage ;;
  deps)
    install_packages "${pkgs_build[@]}" "${pkgs_run[@]}" "${pkgs_test[@]}" "${pkgs_bench[@]}" ;;
  build)
    install_packages "${pkgs_build[@]}" "${pkgs_run[@]}"
    configure_and_build Release ;;
  test)
    install_packages "${pkgs_build[@]}" "${pkgs_run[@]}" "${pkgs_test[@]}" "${pkgs_fuzz[@]}"
    t0=$(date +%s)
    sanitizers=${VTRACK_TEST_SANITIZERS:-1}
    trap stop_background EXIT
    [ "$sanitizers" = 0 ] || start_sanitizer_build
    configure_and_build Release
    start=$(date +%s)
    log "running every test (ctest)"
    ctest --test-dir "$build_dir" --output-on-failure -j "$jobs" "$@"
    log "tests passed in $(( $(date +%s) - start )) s"
    [ "$sanitizers" = 0 ] || sanitizer_tests "$@"
    log "all done in $(( $(date +%s) - t0 )) s" ;;
  bench)
    # Options go to scripts/bench.sh: [--json F] [--all] [--soak-minutes M] [--e2e-scans N].
    install_packages "${pkgs_build[@]}" "${pkgs_run[@]}" "${pkgs_bench[@]}"
    ( install_packages "${pkgs_bench_optional[@]}" ) ||
      log "optional ${pkgs_bench_optional[*]} not installed: the PCL comparison is skipped"
    log "building the benchmarks (Release) in $build_dir with $jobs jobs"
    cmake -S "$here" -B "$build_dir" -DCMAKE_BUILD_TYPE=Release -DVTRACK_BUILD_BENCHMARKS=ON >/dev/null
    cmake --build "$build_dir" -j "$jobs" --target vtrack_bench_programs
    exec "$here/scripts/bench.sh" "$build_dir" "$@" ;;
  fuzz)
    case "${1:-}" in -h|--help) exec "$here/scripts/fuzz.sh" --help ;; esac
    install_packages "${pkgs_build[@]}" "${pkgs_fuzz[@]}"
    exec "$here/scripts/fuzz.sh" "$here" "${1:-60}" ;;
  demo)
    # The demo's --help needs no packages and no build.
    for a in "$@"; do case "$a" in -h|--help) exec "$here/scripts/demo.sh" --help ;; esac; done
    install_packages "${pkgs_build[@]}" "${pkgs_run[@]}"
    # Only the programs the demo runs (the tests take longer to build than they do).
    log "building the demo's programs (Release) in $build_dir with $jobs jobs"
    cmake -S "$here" -B "$build_dir" -DCMAKE_BUILD_TYPE=Release >/dev/null
    cmake --build "$build_dir" -j "$jobs" --target vtrack-ladar-driver vtrack-ego-pose \
      vtrack-sim-log vtrack-tracker vtrack-render vtrack-eval vtrack-monitor vtrack-kitti2lcm
    exec "$here/scripts/demo.sh" "$build_dir" "$@" ;;
  *)
    log "unknown command '$cmd'"
    usage
    exit 2 ;;
esac
