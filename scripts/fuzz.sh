#!/usr/bin/env bash
# Builds the libFuzzer harnesses with clang + ASan/UBSan (in <repo>/build-fuzz) and runs each for
# SECONDS, starting from the seed corpus and the kept regression inputs; the growing corpus is
# kept in build-fuzz/fuzz/corpus/. A crash fails the run and leaves its input in
# build-fuzz/fuzz/crashes/<harness>/: add it to tests/fuzz/regressions/<harness>/ once fixed.
#   usage: fuzz.sh REPO_DIR SECONDS
set -euo pipefail
repo=$1; seconds=$2
bdir=${VTRACK_FUZZ_BUILD_DIR:-$repo/build-fuzz}
jobs=${VTRACK_JOBS:-2}
CC=clang CXX=clang++ cmake -S "$repo" -B "$bdir" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DVTRACK_SANITIZE=ON \
  -DVTRACK_BUILD_FUZZERS=ON -DVTRACK_BUILD_JAVA=OFF -DVTRACK_BUILD_BENCHMARKS=OFF >/dev/null
targets=$(cmake --build "$bdir" --target help | sed -n 's/^\.\.\. \(fuzz-[A-Za-z0-9_]*\).*/\1/p')
cmake --build "$bdir" -j "$jobs" --target vtrack_fuzz_seed_corpus $targets >/dev/null
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
