#!/usr/bin/env bash
# scripts/compare-json: two hand-written summaries whose differences are known; the pooled
# filter; an item or metric on one side only; unreadable input (exit 2).
#   compare_json_test.sh SOURCE_DIR
set -euo pipefail
tool=${1:?usage: compare_json_test.sh SOURCE_DIR}/scripts/compare-json
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
cat > "$dir/base.json" <<'J'
{"fig4_seeds": {"mht": {"mota": 0.5, "hota": 0.75, "false_positives": 10, "false_negatives": 40, "id_switches": 2}},
 "fig4_seed1": {"mht": {"mota": 0.25, "hota": 0.5, "false_positives": 4, "false_negatives": 20, "id_switches": 1}},
 "gone_seeds": {"ism": {"mota": 0.9}}}
J
cat > "$dir/new.json" <<'J'
{"fig4_seeds": {"mht": {"mota": 0.625, "hota": 0.7, "false_positives": 7, "false_negatives": 41, "id_switches": 2},
                "vasm": {"mota": 0.125}},
 "fig4_seed1": {"mht": {"mota": 0.375, "hota": 0.5, "false_positives": 3, "false_negatives": 19, "id_switches": 0}}}
J
fail() { echo "FAIL: $*"; printf '%s\n' "$out"; exit 1; }
expect() {  # ITEM MODE FIELDS...: the row's fields after item and mode, exactly
  local item=$1 mode=$2; shift 2
  local row
  row=$(printf '%s\n' "$out" | awk -v i="$item" -v m="$mode" '$1 == i && $2 == m {$1 = $2 = ""; print substr($0, 3)}')
  [ "$row" = "$*" ] || fail "$item $mode: got '$row', want '$*'"
}
out=$("$tool" "$dir/base.json" "$dir/new.json")
expect fig4_seeds mht 0.500 0.625 +0.125 0.750 0.700 -0.050 10 7 -3 40 41 +1 2 2 +0
expect fig4_seed1 mht 0.250 0.375 +0.125 0.500 0.500 +0.000 4 3 -1 20 19 -1 1 0 -1
expect fig4_seeds vasm - 0.125 - - - - - - - - - - - - -
expect gone_seeds ism 0.900 - - - - - - - - - - - - - -
out=$("$tool" "$dir/base.json" "$dir/new.json" --pooled --metrics mota)
[ "$(printf '%s\n' "$out" | wc -l)" -eq 4 ] || fail "--pooled: want the header and 3 pooled rows"
expect fig4_seeds mht 0.500 0.625 +0.125
printf '%s\n' "$out" | grep -q fig4_seed1 && fail "--pooled printed a single seed's row"
out=$("$tool" "$dir/base.json" "$dir/new.json" --items '^gone')
expect gone_seeds ism 0.900 - - - - - - - - - - - - - -
echo 'not json' > "$dir/bad.json"
set +e
out=$("$tool" "$dir/bad.json" "$dir/new.json" 2>&1); rc=$?
set -e
[ "$rc" -eq 2 ] || fail "malformed input: exit $rc, want 2"
printf '%s\n' "$out" | grep -q "bad.json" || fail "the message does not name the file"
echo "compare-json: every difference as computed by hand"
