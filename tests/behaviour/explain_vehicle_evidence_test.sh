#!/usr/bin/env bash
# scripts/explain-vehicle-evidence against the tracker itself: on a short simulated 64-beam log,
# the script's own walk of the shipped trees must give every logit the tracker recorded in
# --evidence-csv (its cross-check passes, exit 0, and it explains the track with the most rows);
# with the config's 3-D bias moved by 0.5 the same check must fail (exit 1).
#   explain_vehicle_evidence_test.sh BUILD_DIR SOURCE_DIR
set -euo pipefail
build=$1
src=$2
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
"$build/bin/vtrack-sim-log" --scenario residential_street --sensor velodyne64 --seed 5 \
  --duration 3 --out "$work/run.lcm" -q
"$build/bin/vtrack-tracker" --config "$src/config/tracker.yaml" --input "$work/run.lcm" \
  --output "$work/tracks.lcm" --evidence-csv "$work/evidence.csv" -q
track=$(awk -F, 'NR > 1 && $5 == 1 { n[$2]++ } END { for (t in n) if (n[t] > best) { best = n[t]; id = t } print id }' "$work/evidence.csv")
[ -n "$track" ] || { echo "no 3-D evidence rows in the log" >&2; exit 1; }
"$src/scripts/explain-vehicle-evidence" "$work/evidence.csv" --track "$track" \
  --config "$src/config/tracker.yaml" > "$work/out.txt"
cat "$work/out.txt"
grep -q "^track $track: .* per-scan logit mean" "$work/out.txt"
[ "$(grep -c '^[a-z_]* *[-+][0-9]' "$work/out.txt")" -ge 3 ] || { echo "fewer than 3 features explained" >&2; exit 1; }
# The contributions add up to the trees' mean logit of the track (rounding only).
awk '/^expected \+ contributions - mean logit/ { d = $NF; ok = (d < 1e-9 && d > -1e-9) } END { exit !ok }' \
  "$work/out.txt" || { echo "the contributions do not add up to the logit" >&2; exit 1; }
sed -E 's/^(  bias_3d: )([-0-9.e]+)/echo "\1$(python3 -c "print(\2 + 0.5)")"/e' "$src/config/tracker.yaml" > "$work/moved.yaml"
! cmp -s "$src/config/tracker.yaml" "$work/moved.yaml" || { echo "bias_3d not moved" >&2; exit 1; }
set +e
"$src/scripts/explain-vehicle-evidence" "$work/evidence.csv" --track "$track" --config "$work/moved.yaml" \
  > /dev/null 2> "$work/err.txt"
rc=$?
set -e
cat "$work/err.txt"
[ "$rc" -eq 1 ] && grep -q "not the model the tracker ran with" "$work/err.txt" ||
  { echo "a moved bias went unnoticed (exit $rc, not 1 with the model refused)" >&2; exit 1; }
echo "explain-vehicle-evidence: logits agree with the tracker's; a moved bias is refused"
