#!/usr/bin/env bash
# Soak: the tracker on urban_intersection lap after lap for 30 simulated minutes, as fast as the
# machine allows (not part of CI: ~15-30 min of one core). Builds vtrack-soak (Release) and
# prints a line per simulated minute (time per scan, RSS, tracks, ids), then PASS/FAIL for:
# no memory growth, no slow-down, no track id reused, no reset, counters that add up.
#   usage: scripts/soak.sh [vtrack-soak options]    e.g. --minutes 5, --mode ism, --help
# Environment: VTRACK_BUILD_DIR (default ./build), VTRACK_JOBS (default 2).
set -euo pipefail
repo=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
bdir=${VTRACK_BUILD_DIR:-$repo/build}
jobs=${VTRACK_JOBS:-2}
for a in "$@"; do
  case "$a" in
    -h|--help)  # without a build: this header, and vtrack-soak's options where it is built
      sed -n '2,7s/^# \{0,1\}//p' "$0"
      if [ -x "$bdir/tests/vtrack-soak" ]; then echo; exec "$bdir/tests/vtrack-soak" --help; fi
      echo "(vtrack-soak is not built in $bdir yet: its options are listed once it is)"
      exit 0 ;;
  esac
done
cmake -S "$repo" -B "$bdir" -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build "$bdir" -j "$jobs" --target vtrack-soak >/dev/null
exec "$bdir/tests/vtrack-soak" "$@"
