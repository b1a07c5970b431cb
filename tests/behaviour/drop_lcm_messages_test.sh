#!/usr/bin/env bash
# scripts/drop-lcm-messages: a seeded copy removes messages of one channel only and keeps the
# rest byte for byte; it refuses to write over its input, a missing input and a damaged or
# non-LCM one (exit 2, the file named, no traceback).
#   drop_lcm_messages_test.sh BUILD_DIR SOURCE_DIR
set -euo pipefail
build=${1:?usage: drop_lcm_messages_test.sh BUILD_DIR SOURCE_DIR}; tool=${2:?}/scripts/drop-lcm-messages
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
fail() { echo "FAIL: $*"; exit 1; }
"$build/bin/vtrack-sim-log" --scenario paper_fig4_turn --duration 2 --out "$dir/in.lcm" -q
cp "$dir/in.lcm" "$dir/orig.lcm"
out=$("$tool" "$dir/in.lcm" "$dir/all.lcm" LADAR_SCAN 0)
cmp -s "$dir/in.lcm" "$dir/all.lcm" || fail "P = 0 did not copy the log byte for byte"
out=$("$tool" "$dir/in.lcm" "$dir/none.lcm" LADAR_SCAN 1)
n=$(printf '%s' "$out" | sed -n 's/.*removed \([0-9]*\) of \([0-9]*\) LADAR_SCAN.*/\1 \2/p')
set -- $n
[ "${1:-}" -gt 0 ] && [ "$1" = "$2" ] || fail "P = 1 removed '$out'"
[ "$(stat -c %s "$dir/none.lcm")" -lt "$(stat -c %s "$dir/in.lcm")" ] || fail "nothing was removed"
expect_refusal() {  # WHAT NEEDLE ARGS...
  local what=$1 needle=$2 rc=0 msg; shift 2
  msg=$("$tool" "$@" 2>&1) || rc=$?
  [ "$rc" -eq 2 ] || fail "$what: exit $rc, want 2: $msg"
  printf '%s' "$msg" | grep -q "$needle" || fail "$what: '$msg' does not say '$needle'"
  printf '%s' "$msg" | grep -q Traceback && fail "$what: a traceback"
  return 0
}
expect_refusal "its own input" "would destroy the input" "$dir/in.lcm" "$dir/in.lcm" LADAR_SCAN 0.5
cmp -s "$dir/in.lcm" "$dir/orig.lcm" || fail "the input was changed"
expect_refusal "a missing input" "missing.lcm: no such log file" "$dir/missing.lcm" "$dir/o.lcm" X 0.5
head -c 3000 /dev/urandom > "$dir/random.lcm"
expect_refusal "random bytes" "random.lcm: not an LCM log" "$dir/random.lcm" "$dir/o.lcm" X 0.5
echo "drop-lcm-messages: copies, removes and refuses as it should"
