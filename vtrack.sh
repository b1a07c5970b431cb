#!/usr/bin/env bash
# vtrack: the one entry point. Installs what is missing (Debian 12 packages), builds, and runs.
#
#   ./vtrack.sh demo [DEMO OPTIONS]   the main job (see ./vtrack.sh demo --help)
#   ./vtrack.sh test [CTEST ARGS]     every test (CI); VTRACK_TEST_SANITIZERS=1: then again under
#                                     ASan+UBSan + short fuzzing
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
pkgs_build=(g++ make cmake pkg-config
  liblcm-dev liblcm-bin liblcm-java
  libeigen3-dev libyaml-cpp-dev libboost-program-options-dev
  libopencv-core-dev libopencv-imgproc-dev libopencv-imgcodecs-dev libopencv-videoio-dev
  libgtest-dev libbenchmark-dev default-jdk-headless)
pkgs_run=(iproute2 procps zstd tar)
pkgs_test=(xvfb xauth default-jre libjchart2d-java nftables)
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
# (whose UBSan also checks float-to-int overflow), -O1 with line tables and asserts on, no
# benchmarks (nothing they test that the tests do not), in its own tree; then a short smoke run
# of every libFuzzer harness from the same tree (coverage from the harness files only: compiling
# the libraries with coverage would cost more than the run; ./vtrack.sh fuzz has it all).
# Off by default (VTRACK_TEST_SANITIZERS=1 turns it on): on a clean clone the whole sanitizer
# suite passes except the tests that track live against the wall clock (tracker_live_test: the
# -O1 instrumented tracker cannot keep up with real-time 64-layer scans) and those still
# unchecked after it; see docs/reliability.md. It goes back on by default once they are.
sanitizer_tests() {
  local sdir=${VTRACK_SANITIZE_BUILD_DIR:-$build_dir-asan} start
  log "building with ASan + UBSan (clang) in $sdir with $jobs jobs"
  CC=clang CXX=clang++ cmake -S "$here" -B "$sdir" -DCMAKE_BUILD_TYPE=RelWithDebInfo \
    -DCMAKE_C_FLAGS_RELWITHDEBINFO="-O1 -gline-tables-only" \
    -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -gline-tables-only" \
    -DVTRACK_SANITIZE=ON -DVTRACK_BUILD_FUZZERS=ON -DVTRACK_FUZZ_COVERAGE=OFF \
    -DVTRACK_BUILD_BENCHMARKS=OFF >/dev/null
  cmake --build "$sdir" -j "$jobs"
  start=$(date +%s)
  log "running every test under ASan + UBSan"
  ctest --test-dir "$sdir" --output-on-failure -j "$jobs" "$@"
  log "sanitizer tests passed in $(( $(date +%s) - start )) s"
  log "fuzzing every harness for ${VTRACK_FUZZ_SECONDS:-10} s"
  VTRACK_FUZZ_BUILD_DIR=$sdir "$here/scripts/fuzz.sh" "$here" "${VTRACK_FUZZ_SECONDS:-10}"
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
    configure_and_build Release
    start=$(date +%s)
    log "running every test (ctest)"
    ctest --test-dir "$build_dir" --output-on-failure -j "$jobs" "$@"
    log "tests passed in $(( $(date +%s) - start )) s"
    [ "${VTRACK_TEST_SANITIZERS:-0}" = 0 ] || sanitizer_tests "$@"
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
