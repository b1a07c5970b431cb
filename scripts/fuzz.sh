#!/usr/bin/env bash
# Builds the libFuzzer harnesses with clang + ASan/UBSan (in <repo>/build-fuzz) and runs each for
# SECONDS, starting from the seed corpus and the kept regression inputs; the growing corpus is
# kept in build-fuzz/fuzz/corpus/. A crash fails the run and leaves its input in
# build-fuzz/fuzz/crashes/<harness>/: add it to tests/fuzz/regressions/<harness>/ once fixed.
#   usage: fuzz.sh REPO_DIR SECONDS
# VTRACK_FUZZ_BUILD_DIR: another tree; VTRACK_FUZZ_PREBUILT=1: that tree is configured and built
# already (CI's sanitizer tree, while its tests run): neither reconfigure nor build it.
set -euo pipefail
case "${1:-}" in -h|--help) sed -n '2,8s/^# \{0,1\}//p' "$0"; exit 0 ;; esac
if [ $# -ne 2 ] || ! [ -d "$1" ] || ! [[ $2 =~ ^[0-9]+$ ]] || [ "$2" -lt 1 ]; then
  echo "usage: fuzz.sh REPO_DIR SECONDS (a source tree and a whole number of seconds per harness; --help)" >&2
  exit 2
fi
repo=$1; seconds=$2
bdir=${VTRACK_FUZZ_BUILD_DIR:-$repo/build-fuzz}
jobs=${VTRACK_JOBS:-2}
if [ "${VTRACK_FUZZ_PREBUILT:-0}" = 0 ]; then
  CC=clang CXX=clang++ cmake -S "$repo" -B "$bdir" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DVTRACK_SANITIZE=ON \
    -DVTRACK_BUILD_FUZZERS=ON -DVTRACK_BUILD_JAVA=OFF -DVTRACK_BUILD_BENCHMARKS=OFF >/dev/null
  targets=$(cmake --build "$bdir" --target help | sed -n 's/^\.\.\. \(fuzz-[A-Za-z0-9_]*\).*/\1/p')
  [ -z "$targets" ] || cmake --build "$bdir" -j "$jobs" --target vtrack_fuzz_seed_corpus $targets >/dev/null
else
  targets=$(cd "$bdir/fuzz" 2>/dev/null && for f in fuzz-*; do [ -x "$f" ] && echo "$f"; done || true)
fi
if [ -z "$targets" ]; then
  echo "fuzz.sh: no fuzz-* harnesses in $bdir (built with clang and -DVTRACK_BUILD_FUZZERS=ON?)" >&2
  exit 1
fi
status=0
printf '%-28s %12s %8s %s\n' harness executions cov result
for t in $targets; do
  name=${t#fuzz-}
  corpus=$bdir/fuzz/corpus/$name; crashes=$bdir/fuzz/crashes/$name
  mkdir -p "$corpus" "$crashes"
  seeds=()
  [ -d "$bdir/fuzz/seeds/$name" ] && seeds+=("$bdir/fuzz/seeds/$name")
  [ -d "$repo/tests/fuzz/regressions/$name" ] && seeds+=("$repo/tests/fuzz/regressions/$name")
  log=$bdir/fuzz/$name.log
  set +e
  "$bdir/fuzz/$t" -max_total_time="$seconds" -rss_limit_mb=2048 -malloc_limit_mb=1024 \
    -print_final_stats=1 -artifact_prefix="$crashes/" "$corpus" "${seeds[@]}" >"$log" 2>&1
  rc=$?
  set -e
  execs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -1)
  cov=$(grep -o 'cov: [0-9]*' "$log" | tail -1 | cut -d' ' -f2)
  if [ $rc -eq 0 ]; then result=ok; else result="CRASH (see $log)"; status=1; fi
  printf '%-28s %12s %8s %s\n' "$name" "${execs:-?}" "${cov:-?}" "$result"
done
exit $status
