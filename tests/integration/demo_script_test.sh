#!/usr/bin/env bash
# scripts/demo.sh (./vtrack.sh demo) on a short lap of paper_fig4_turn: it exits 0 with the
# summary, writes the log, video, PNGs and metrics it names, and leaves no process behind; then
# Ctrl-C (SIGINT to its process group, as a terminal sends it) during a run stops every process
# and exits 130; and bad options exit 2. The demo makes its own private network namespace.
#
#   usage: demo_script_test.sh SOURCE_DIR BUILD_DIR
set -euo pipefail
src=${1:?usage: demo_script_test.sh SOURCE_DIR BUILD_DIR}
build=${2:?usage: demo_script_test.sh SOURCE_DIR BUILD_DIR}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail=0
bad() { echo "FAIL: $*" >&2; fail=1; }
# Every process the demo starts inherits DEMO_TEST_TAG: any left is found by its environment.
left_over() {
  local e p
  for e in /proc/[0-9]*/environ; do
    p=${e#/proc/}; p=${p%/environ}
    [ "$p" = $$ ] && continue
    if { tr '\0' '\n' < "$e"; } 2>/dev/null | grep -qx "DEMO_TEST_TAG=$1"; then
      echo "$p $(tr '\0' ' ' < "/proc/$p/cmdline" 2>/dev/null)"
    fi
  done
}

# Is a private network namespace possible here? (demo.sh exits 77 otherwise)
"$src/scripts/vtrack-netns" true || { rc=$?; [ $rc = 77 ] && { echo "no private network namespace: skipped"; exit 77; }; exit $rc; }

# 1. A whole (short) run.
out=$tmp/run
set +e
DEMO_TEST_TAG=$out "$src/scripts/demo.sh" "$build" --scenario paper_fig4_turn --duration 4 --out "$out" > "$tmp/demo.txt" 2>&1
rc=$?
set -e
[ $rc = 0 ] || { cat "$tmp/demo.txt" >&2; bad "demo exited $rc"; }
for f in run.lcm demo.mp4 metrics.json tracks.csv summary.txt plots/detections_over_time.png; do
  [ -s "$out/$f" ] || bad "no $out/$f"
done
ls "$out"/png/frame_*.png > /dev/null 2>&1 || bad "no PNGs in $out/png"
grep -q "^vtrack demo: paper_fig4_turn" "$tmp/demo.txt" || bad "no summary title"
# 4 s at 25 Hz: 100 scans, every one answered by the tracker and scored.
grep -Eq "scans with truth and tracks +100$" "$tmp/demo.txt" || bad "not 100 scans scored: $(grep 'scans with' "$tmp/demo.txt")"
grep -Eq "MOTA +-?[0-9]+\.[0-9]{3}$" "$tmp/demo.txt" || bad "no MOTA in the summary"
for f in "$out/run.lcm" "$out/demo.mp4" "$out/metrics.json"; do
  grep -qF "$f" "$tmp/demo.txt" || bad "the summary does not name $f"
done
[ -z "$(left_over "$out")" ] || bad "processes left after the demo: $(left_over "$out")"

# 2. Ctrl-C in the middle of a run: SIGINT to the demo's whole process group.
out2=$tmp/interrupted
set -m  # job control: the demo gets its own process group, and SIGINT is not ignored in it
DEMO_TEST_TAG=$out2 "$src/scripts/demo.sh" "$build" --scenario paper_fig4_turn --out "$out2" > "$tmp/int.txt" 2>&1 &
pgid=$!
set +m
for _ in $(seq 1 300); do  # until the lap runs (the driver has started)
  grep -q "starting vtrack-ego-pose" "$tmp/int.txt" 2>/dev/null && break
  sleep 0.1
done
sleep 3
kill -INT -- -"$pgid"
set +e
wait "$pgid"
rc=$?
set -e
[ $rc = 130 ] || { cat "$tmp/int.txt" >&2; bad "interrupted demo exited $rc, not 130"; }
grep -q "interrupted: stopping every process" "$tmp/int.txt" || bad "no word of the interruption"
[ -z "$(left_over "$out2")" ] || bad "processes left after Ctrl-C: $(left_over "$out2")"

# 3. Bad options: exit 2 with a message naming the value.
for args in "--scenario no_such_scene" "--duration -1" "--mode fast" "--bogus"; do
  set +e
  # shellcheck disable=SC2086
  msg=$("$src/scripts/demo.sh" "$build" $args --out "$tmp/bad" 2>&1)
  rc=$?
  set -e
  [ $rc = 2 ] || bad "'$args' exited $rc, not 2"
  value=${args##* }
  grep -qF -- "$value" <<< "$msg" || bad "'$args': the message does not name '$value': $msg"
done

[ $fail = 0 ] && echo "demo script: OK"
exit $fail
