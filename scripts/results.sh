#!/usr/bin/env bash
# Regenerates docs/results.md: the tracker's accuracy in its three modes (vtrack-compare on the
# simulated scenes and, when present, the real KITTI data), the integration tests' per-vehicle
# scores (tracker-eval-scores) and, with --bench, the benchmarks. The file records the date, the
# git commit and the exact commands, so that every figure in it can be reproduced.
#
#   usage: scripts/results.sh [OPTIONS]
#
# Options:
#   --build DIR        build tree [./build]; needs bin/vtrack-{compare,sim-log,tracker,eval,kitti2lcm}
#                      and, for the per-vehicle table, tests/tracker-eval-scores
#   --out F            the markdown file to write [docs/results.md]
#   --scenarios LIST   simulated scenes, comma separated
#                      [paper_fig4_turn,paper_fig5_follow_clutter,paper_fig6_noisy_follow,urban_intersection]
#   --modes LIST       tracker modes [ism,vasm,mht]
#   --seed N           seed of the simulator and the tracker's random draws [1]
#   --draws LIST       two or more seeds for the spread table [1,2,3,4,5]: every scene and KITTI
#                      0000 (scans) once per seed (vtrack-compare --seeds: the simulator's noise and
#                      the fits' random draws), their counts pooled; "" leaves the table out
#   --data DIR         real data [../shared/data]: kitti_tracking_0000 (scans) and
#                      kitti_tracking_boxes (detector boxes) are used when present
#   --no-kitti         leave the real data out
#   --bench            also run the benchmarks (scripts/bench.sh, about 10 minutes; needs the
#                      benchmark programs: ./vtrack.sh bench builds them, or
#                      cmake --build BUILD --target vtrack_bench_programs)
#   --bench-json F     take the speed table from this bench-results.json (from ./vtrack.sh bench
#                      or scripts/bench.sh) instead of running the benchmarks
#   --work-dir DIR     keep the logs and JSON here [a temporary directory, removed at the end]
#   -h, --help         this help
#
# Without --bench the run takes several minutes on 2 cores and about 2.5 GB in the work
# directory (urban_intersection's 64-layer log is 1.7 GB, KITTI 0000's 0.4 GB). Progress goes
# to stderr; the markdown is written only when every step succeeded.
#
# Exit status: 0 written; 1 a tool failed (nothing is written); 2 bad option or missing build.
set -euo pipefail

here=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
usage() { awk 'NR > 1 && /^#/ { sub(/^# ?/, ""); print; next } NR > 1 { exit }' "$0"; }
die() { echo "results.sh: $1" >&2; exit "${2:-1}"; }
say() { printf '\033[1m[results]\033[0m %s\n' "$*" >&2; }

build=$here/build
out=$here/docs/results.md
scenarios=paper_fig4_turn,paper_fig5_follow_clutter,paper_fig6_noisy_follow,urban_intersection
modes=ism,vasm,mht
seed=1
draws=1,2,3,4,5
data=$here/../shared/data
use_kitti=1
bench=0
bench_json=
work=
args=("$@")
while [ $# -gt 0 ]; do
  case "$1" in
    --build) [ $# -ge 2 ] || die "--build needs a directory" 2; build=$2; shift 2 ;;
    --out) [ $# -ge 2 ] || die "--out needs a file" 2; out=$2; shift 2 ;;
    --scenarios) [ $# -ge 2 ] || die "--scenarios needs a list" 2; scenarios=$2; shift 2 ;;
    --modes) [ $# -ge 2 ] || die "--modes needs a list" 2; modes=$2; shift 2 ;;
    --seed) [ $# -ge 2 ] || die "--seed needs a number" 2; seed=$2; shift 2 ;;
    --draws) [ $# -ge 2 ] || die "--draws needs a list (or '')" 2; draws=$2; shift 2 ;;
    --data) [ $# -ge 2 ] || die "--data needs a directory" 2; data=$2; shift 2 ;;
    --no-kitti) use_kitti=0; shift ;;
    --bench) bench=1; shift ;;
    --bench-json) [ $# -ge 2 ] || die "--bench-json needs a file" 2; bench_json=$2; shift 2 ;;
    --work-dir) [ $# -ge 2 ] || die "--work-dir needs a directory" 2; work=$2; shift 2 ;;
    -h|--help) usage; exit 0 ;;
    *) die "unknown option '$1' (see --help)" 2 ;;
  esac
done
[[ $seed =~ ^[0-9]+$ ]] || die "--seed '$seed' is not a number" 2
[ -z "$draws" ] || [[ $draws =~ ^[0-9]+(,[0-9]+)+$ ]] || die "--draws '$draws' is not a list of two or more numbers" 2
[ "$bench" = 0 ] || [ -z "$bench_json" ] || die "--bench and --bench-json exclude each other" 2
[ -z "$bench_json" ] || [ -s "$bench_json" ] || die "--bench-json: no file '$bench_json'" 2
command -v jq >/dev/null || die "jq is needed (apt-get install jq)" 2

# ---- the build ---------------------------------------------------------------------------------
build_hint="cmake -S . -B build -DCMAKE_BUILD_TYPE=Release && cmake --build build -j2 --target vtrack-compare vtrack-sim-log vtrack-tracker vtrack-eval vtrack-kitti2lcm tracker-eval-scores"
[ -d "$build" ] || die "no build directory '$build'; build first:
  $build_hint" 2
build=$(cd "$build" && pwd)
for tool in vtrack-compare vtrack-sim-log vtrack-tracker vtrack-eval vtrack-kitti2lcm; do
  [ -x "$build/bin/$tool" ] || die "$build/bin/$tool is missing; build it:
  $build_hint" 2
done
scorer=$build/tests/tracker-eval-scores
[ -x "$scorer" ] || { say "$scorer is not built: the per-vehicle table is left out"; scorer=; }
build_type=$(sed -n 's/^CMAKE_BUILD_TYPE:[A-Z]*=//p' "$build/CMakeCache.txt" 2>/dev/null || true)
cxx=$(sed -n 's/^CMAKE_CXX_COMPILER:[A-Z]*=//p' "$build/CMakeCache.txt" 2>/dev/null || true)
cxx_version=$({ [ -n "$cxx" ] && "$cxx" --version 2>/dev/null | head -1; } || echo "unknown compiler")
[ "$build_type" = Release ] || say "warning: build type is '${build_type:-unknown}', not Release"

# Paths as written in the file: relative to the repository (../shared/data stays so), else absolute.
rel() {
  local r
  r=$(realpath -m --relative-to="$here" "$1")
  case "$r" in ../../*) realpath -m "$1" ;; *) echo "$r" ;; esac
}
B=$(rel "$build")

# ---- the work directory ------------------------------------------------------------------------
if [ -z "$work" ]; then
  work=$(mktemp -d "${TMPDIR:-/tmp}/vtrack-results-XXXXXX")
  trap 'rm -rf "$work"' EXIT
else
  mkdir -p "$work" || die "cannot create --work-dir '$work'" 2
  work=$(cd "$work" && pwd)
fi

# The tree the figures come from (checked before the output file is rewritten).
commit=$(git -C "$here" rev-parse --short HEAD 2>/dev/null || echo unknown)
dirty=$(git -C "$here" status --porcelain 2>/dev/null | grep -v " $(rel "$out")\$" || true)
[ -z "$dirty" ] || commit="$commit (with uncommitted changes)"
started=$SECONDS

# ---- 1. simulated scenes (+ KITTI 0000) in every mode --------------------------------------------
compare_args=(--scenarios "$scenarios" --modes "$modes" --seed "$seed")
kitti_dir=$data/kitti_tracking_0000
boxes_dir=$data/kitti_tracking_boxes
what=$scenarios
if [ "$use_kitti" = 1 ] && [ -d "$kitti_dir" ]; then
  compare_args+=(--kitti "$(rel "$kitti_dir")" --kitti-input-modes scans,boxes,fused)
  what+=",KITTI 0000 (scans; detector boxes; both fused)"
elif [ "$use_kitti" = 1 ]; then
  say "no $kitti_dir: KITTI 0000 is left out"
fi
say "vtrack-compare on $what in modes $modes (the longest step)"
( cd "$here" && "$build/bin/vtrack-compare" "${compare_args[@]}" --json "$work/compare.json" \
    --work-dir "$work/runs" --keep-work ) >"$work/compare.txt" \
  || die "vtrack-compare failed (its output above; logs in $work/runs)"
compare_cmd="$B/bin/vtrack-compare ${compare_args[*]} --json WORK/compare.json --work-dir WORK/runs"

# ---- 1b. the same, once per seed: how far one run's figures move from draw to draw -------------
draws_cmd=
if [ -n "$draws" ]; then
  draws_args=(--scenarios "$scenarios" --modes "$modes" --seeds "$draws")
  if [ "$use_kitti" = 1 ] && [ -d "$kitti_dir" ]; then draws_args+=(--kitti "$(rel "$kitti_dir")"); fi
  say "vtrack-compare once per seed $draws (the spread table)"
  ( cd "$here" && "$build/bin/vtrack-compare" "${draws_args[@]}" --json "$work/draws.json" \
      --work-dir "$work/draws" ) >"$work/draws.txt" \
    || die "vtrack-compare --seeds failed (its output in $work/draws.txt)"
  rm -rf "$work/draws"  # several GB of logs
  draws_cmd="$B/bin/vtrack-compare ${draws_args[*]} --json WORK/draws.json"
fi

# ---- 2. per-vehicle scores of the same logs -------------------------------------------------------
scores_md=
if [ -n "$scorer" ]; then
  scores_md="| scenario | mode | tracked | id switches | pos RMSE [m] | heading RMSE axis / movers [deg] |
| --- | --- | --- | --- | --- | --- |"
  for item in $(jq -r 'keys_unsorted[]' "$work/compare.json"); do
    for mode in ${modes//,/ }; do
      tracks=$work/runs/$item/tracks_$mode.lcm
      [ -s "$tracks" ] || continue
      say "tracker-eval-scores $item / $mode"
      # sed, not head: head would close the pipe early and the scorer die of SIGPIPE (pipefail).
      line=$("$scorer" "$work/runs/$item/run.lcm" "$tracks" | sed -n 1p) \
        || die "tracker-eval-scores failed on $item / $mode"
      row=$(sed -nE 's/^due ([0-9]+), matched ([0-9]+) \([^)]*\), id switches ([0-9]+), pos RMSE ([-0-9.na]+) m, heading RMSE ([-0-9.na]+) deg \(axis\), mover heading RMSE ([-0-9.na]+) deg.*/| \2\/\1 | \3 | \4 | \5 \/ \6 |/p' <<<"$line")
      [ -n "$row" ] || die "tracker-eval-scores printed an unexpected line: $line"
      scores_md+=$'\n'"| $item | $mode $row"
    done
  done
fi

# ---- 3. box input on the KITTI boxes sequences -----------------------------------------------------
boxes_cmd=
if [ "$use_kitti" = 1 ] && [ -d "$boxes_dir" ]; then
  # The constant-velocity reference of 3-D MOT papers beside the paper's modes.
  boxes_modes=$modes
  case ",$modes," in *,cv,*) ;; *) boxes_modes=cv,$modes ;; esac
  boxes_args=(--kitti-boxes "$(rel "$boxes_dir")" --modes "$boxes_modes")
  say "vtrack-compare on the KITTI boxes sequences (detector boxes, --input-mode boxes)"
  ( cd "$here" && "$build/bin/vtrack-compare" "${boxes_args[@]}" --json "$work/boxes.json" \
      --work-dir "$work/boxes" --keep-work ) >"$work/boxes.txt" \
    || die "vtrack-compare --kitti-boxes failed (logs in $work/boxes)"
  boxes_cmd="$B/bin/vtrack-compare ${boxes_args[*]} --json WORK/boxes.json --work-dir WORK/boxes"
elif [ "$use_kitti" = 1 ]; then
  say "no $boxes_dir: the box-input table is left out"
fi

# ---- 4. benchmarks ----------------------------------------------------------------------------------
bench_cmd=
if [ "$bench" = 1 ]; then
  [ -x "$build/bench/tracker_bench" ] || die "the benchmark programs are not built; build them:
  cmake --build $B -j2 --target vtrack_bench_programs" 2
  say "benchmarks (scripts/bench.sh, about 10 minutes)"
  "$here/scripts/bench.sh" "$build" --json "$work/bench-results.json" >&2 \
    || die "scripts/bench.sh failed"
  bench_json=$work/bench-results.json
  bench_cmd="scripts/bench.sh $B --json bench-results.json"
elif [ -n "$bench_json" ]; then
  bench_cmd="scripts/bench.sh $B --json bench-results.json   # or ./vtrack.sh bench; read from $(rel "$bench_json")"
fi

# ---- the file ---------------------------------------------------------------------------------------
# Markdown table of a vtrack-compare JSON: one row per item and mode.
compare_table() {
  jq -r '
    def f($x; $d): if $x == null then "-" else ($x * pow(10; $d) | round / pow(10; $d) | tostring) end;
    def g($x): if $x == null then "-" elif $x < 10 then f($x; 2) elif $x < 100 then f($x; 1) else f($x; 0) end;
    "| item | mode | MOTA | IDSW | MT/ML | HOTA | pos [m] | head [deg] | pred 1 s [m] | NEES mean | NEES in 95% |",
    "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |",
    (to_entries[] | select(.key != "kitti_boxes_iou") | .key as $item | .value | to_entries[] | .key as $mode | .value as $s |
      if $s == null then "| \($item) | \($mode) | failed | | | | | | | | |"
      else "| \($item) | \($mode) | \(f($s.mota; 3)) | \($s.id_switches) | \($s.mostly_tracked)/\($s.mostly_lost) | \(f($s.hota; 3)) | \(f($s.position_rmse_m; 3)) | \(f($s.heading_rmse_deg; 2)) | \(f($s.prediction_error_m."1"; 3)) | \(g($s.nees_mean)) | \(f($s.nees_within_95; 3)) |"
      end)' "$1"
}

# The boxes sequences under KITTI's 3-D criterion (vtrack-eval-kitti, from vtrack-compare's JSON)
# per mode, with the prediction errors of the sum, all and split by the truth's motion, and
# AB3DMOT's published car figures from the same detector on the other (validation) sequences.
iou_table() {
  jq -r '
    def f($x; $d): if $x == null then "-" else ($x * pow(10; $d) | round / pow(10; $d) | tostring) end;
    def p($x): f(if $x == null then null else 100 * $x end; 2);
    def pe($e): "\(f($e."1"; 2)) / \(f($e."2"; 2)) / \(f($e."3"; 2))";
    def ps($e): "\(f($e."1".error_m; 2)) / \(f($e."2".error_m; 2)) / \(f($e."3".error_m; 2))";
    . as $root |
    "| mode | sAMOTA | AMOTA | MOTA | IDS | FRAG | FP | FN | pred 1/2/3 s [m] | turning 1/2/3 s [m] | straight 1/2/3 s [m] |",
    "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |",
    ($root.kitti_boxes_iou | to_entries[] | .key as $mode | .value.all as $a | $root.kitti_boxes_sum[$mode] as $s |
      "| \($mode) | \(p($a.samota)) | \(p($a.amota)) | \(p($a.mota)) | \($a.ids) | \($a.frag) | \($a.fp) | \($a.fn) | \(if $s == null then "-" else pe($s.prediction_error_m) end) | \(if $s == null then "-" else ps($s.prediction_turning) end) | \(if $s == null then "-" else ps($s.prediction_straight) end) |"),
    "| AB3DMOT (published; validation sequences) | 93.34 | - | 86.47 | 0 | - | - | - | - | - | - |",
    "",
    "Prediction samples (all / turning / straight, at 1 s): " +
      ([$root.kitti_boxes_sum | to_entries[] | select(.value != null) | "\(.key) \(.value.prediction_samples."1") / \(.value.prediction_turning."1".samples) / \(.value.prediction_straight."1".samples)"] | join("; "))' "$1"
}

# The pooled rows (<item>_seeds) of a vtrack-compare --seeds JSON, with each draw's MOTA.
draws_table() {
  jq -r '
    def f($x; $d): if $x == null then "-" else ($x * pow(10; $d) | round / pow(10; $d) | tostring) end;
    . as $root |
    "| item | mode | MOTA pooled | MOTA per seed | HOTA mean | IDSW (sum) | FP / FN (sum) |",
    "| --- | --- | --- | --- | --- | --- | --- |",
    (to_entries[] | select(.key | endswith("_seeds")) | (.key | sub("_seeds$"; "")) as $item | .value | to_entries[] |
      .key as $mode | .value as $s |
      ([$root | to_entries[] | select(.key | test("^" + $item + "_seed[0-9]+$")) |
        .value[$mode] | if . == null then "failed" else f(.mota; 3) end] | join(" / ")) as $per |
      if $s == null then "| \($item) | \($mode) | failed | \($per) | | | |"
      else "| \($item) | \($mode) | \(f($s.mota; 3)) | \($per) | \(f($s.hota; 3)) | \($s.id_switches) | \($s.false_positives) / \($s.false_negatives) |"
      end)' "$1"
}

bench_table() {
  jq -r '
    def f($x; $d): if $x == null then "n/a" else ($x * pow(10; $d) | round / pow(10; $d) | tostring) end;
    def ok($c): if $c == null then "" elif $c then "met" else "missed" end;
    def le($x; $t): if $x == null then null else $x <= $t end;
    "| measure | value | target |",
    "| --- | --- | --- |",
    "| KITTI 0000 ms/scan (CPU, one thread) median / p99 | \(f(.kitti_ms_per_scan_median; 2)) / \(f(.kitti_ms_per_scan_p99; 2)) | 6 / 10: \(ok(if .kitti_ms_per_scan_median == null or .kitti_ms_per_scan_p99 == null then null else .kitti_ms_per_scan_median <= 6 and .kitti_ms_per_scan_p99 <= 10 end)) |",
    "| KITTI 0000, 2 threads, scans back to back (as offline): CPU of both median; wall median / p99 | \(f(.kitti_2threads_cpu_ms_median; 2)); \(f(.kitti_2threads_wall_ms_median; 2)) / \(f(.kitti_2threads_wall_ms_p99; 2)) | |",
    "| KITTI 0000, 2 threads, scans 100 ms apart (as live): wall median / p99, pinned (shipped) / unpinned | \(f(.kitti_2threads_10hz_wall_ms_median; 2)) / \(f(.kitti_2threads_10hz_wall_ms_p99; 2)); \(f(.kitti_2threads_10hz_unpinned_wall_ms_median; 2)) / \(f(.kitti_2threads_10hz_unpinned_wall_ms_p99; 2)) | |",
    "| KITTI returns / tracks per scan | \(f(.kitti_points_per_scan; 0)) / \(f(.kitti_tracks_per_scan; 0)) | |",
    "| KITTI stages ms (one thread): preprocess / segmentation + range profile / association / updates / new tracks / life cycle + report | \(if .kitti_stage_ms == null then "n/a" elif .kitti_stage_ms.updates == null then "\(f(.kitti_stage_ms.preprocess; 2)) / \(f(.kitti_stage_ms.segmentation; 2)) / \(f(.kitti_stage_ms.association; 2)) / \(f(.kitti_stage_ms.updates_and_rest; 2)) (updates and the rest)" else "\(f(.kitti_stage_ms.preprocess; 2)) / \(f(.kitti_stage_ms.segmentation; 2)) / \(f(.kitti_stage_ms.association; 2)) / \(f(.kitti_stage_ms.updates; 2)) / \(f(.kitti_stage_ms.new_tracks; 2)) / \(f(.kitti_stage_ms.life_cycle; 2))" end) | |",
    "| stress ms/scan median / p99 | \(f(.stress_ms_per_scan_median; 2)) / \(f(.stress_ms_per_scan_p99; 2)) | 6: \(ok(le(.stress_ms_per_scan_median; 6))) |",
    "| paper_fig4_turn ms/scan median | \(f(.fig4_ms_per_scan_median; 3)) | |",
    "| boxes only (detector boxes, KITTI 0020, 837 frames): frames/s (CPU) \(.boxes_frames_per_s // {} | keys_unsorted | join(" / ")) | \(.boxes_frames_per_s // {} | to_entries | map(f(.value; 0)) | join(" / ")) | 2000 (mht): \(ok(if .boxes_frames_per_s.mht == null then null else .boxes_frames_per_s.mht >= 2000 end)) |",
    "| copy floor ms/scan; tracker / copy floor | \(f(.copy_floor_ms_per_scan; 3)); \(f(.copy_floor_ratio; 1)) | 10: \(ok(le(.copy_floor_ratio; 10))) |",
    "| points 10k..1M: ms/scan; growth exponent | \(.points_scaling | map("\(f(.ms; 1))") | join(" / ")); \(f(.points_growth_exponent; 2)) | ~1: \(ok(le(.points_growth_exponent; 1.2))) |",
    "| objects 10..1000: ms/scan; growth exponent | \(.objects_scaling | map("\(f(.ms; 1))") | join(" / ")); \(f(.objects_growth_exponent; 2)) | |",
    "| PCL Euclidean clustering / grid segmentation (ms) | \(f(.pcl_cluster_ms; 1)) / \(f(.grid_cluster_ms; 2)) = \(f(.pcl_cluster_speed_ratio; 0))x | > 1 |",
    "| PCL VoxelGrid (0.2 m) + Euclidean (0.5 m) / vtrack whole tracker, per raw KITTI sweep (ms) | \(f(.pcl_pipeline_ms; 1)) / \(f(.vtrack_pipeline_ms; 1)) = \(f(.pcl_pipeline_ratio; 1))x | |",
    "| cluster agreement: adjusted Rand index; segments matched | \(f(.pcl_adjusted_rand_index; 3)); \(f(.pcl_segments_matched; 3)) | |",
    "| e2e latency over LCM, KITTI at 10 Hz, whole sweeps, ms median / p99 (in the tracker) | \(f(.e2e_latency_ms_median; 2)) / \(f(.e2e_latency_ms_p99; 2)) (\(f(.e2e_tracker_ms_median; 2)) / \(f(.e2e_tracker_ms_p99; 2))) | p99 < 20: \(ok(if .e2e_latency_ms_p99 == null then null else .e2e_latency_ms_p99 < 20 end)) |",
    "| the same, sweeps in \(f(.e2e_sliced_slices_per_scan; 1)) slices | \(f(.e2e_sliced_latency_ms_median; 2)) / \(f(.e2e_sliced_latency_ms_p99; 2)) (\(f(.e2e_sliced_tracker_ms_median; 2)) / \(f(.e2e_sliced_tracker_ms_p99; 2))) | p99 < 20: \(ok(if .e2e_sliced_latency_ms_p99 == null then null else .e2e_sliced_latency_ms_p99 < 20 end)) |",
    "| RSS over 10 simulated minutes of stress, MB start / half time / end / peak; growth from minute 1, over the second half | \(f(.rss_start_mb; 1)) / \(f(.rss_half_mb; 1)) / \(f(.rss_end_mb; 1)) / \(f(.rss_peak_mb; 1)); \(f(.rss_growth_pct; 2))%, \(f(.rss_growth_second_half_pct; 2))% | ~0 (second half) |",
    (.models_us // {} | to_entries[] | select(.key | test("PredictUpdate")) | "| EKF \(.key) [us] | \(f(.value; 2)) | |"),
    (.notes // [] | .[] | "| note | \(.) | |")' "$1"
}

say "writing $(rel "$out")"
mkdir -p "$(dirname "$out")"
{
  cat <<EOF
# Results

This file is written by \`scripts/results.sh\` (\`scripts/results.sh --help\`); edit the script,
not the file. Rerun it to measure the current tree.

- date: $(date -u +%Y-%m-%d) (UTC)
- commit: $commit
- command: \`scripts/results.sh${args[*]:+ ${args[*]}}\`
- build: \`$B\`, ${build_type:-unknown}, $cxx_version; $(nproc) cores

WORK below is the script's work directory (\`--work-dir\`). What each metric means:
[log_tools/README.md](../log_tools/README.md); the scenes: [sensor_driver/README.md](../sensor_driver/README.md).

## Tracking accuracy, three modes side by side

\`vtrack-eval\` scoring: confirmed tracks classed vehicle, CLEAR MOT gate 2 m, all ranges; KITTI:
cars and vans within 40 m in camera 2's view, unmatched tracks in DontCare regions not counted
(as the KITTI devkit; log_tools/README.md). Seed $seed (the simulator's and the tracker's).

\`\`\`sh
$compare_cmd
\`\`\`

$(compare_table "$work/compare.json")
EOF
  if [ -n "$draws_cmd" ]; then
    cat <<EOF

## Spread from draw to draw

One run is one draw: of the simulator's sensor noise and, in every item, of the fits' random
draws (RANSAC; \`vtrack-tracker --seed\`). The tracker's decisions are discrete (a track
confirmed, split, classed or deleted a scan earlier or later), so a scene's figures move from
draw to draw by more than most changes of the tracker move them: compare changes on the pooled
rows. Each item once per seed $draws; MOTA pooled from the CLEAR MOT counts summed over the
seeds, HOTA the mean of the seeds' values.

\`\`\`sh
$draws_cmd
\`\`\`

$(draws_table "$work/draws.json")
EOF
  fi
  if [ -n "$scores_md" ]; then
    cat <<EOF

## Per-vehicle criterion of the integration tests

Vehicles within 40 m of the ego, from 1 s after they come into view, matched one to one with
non-tentative tracks within 2 m; tracked = matched / due (vehicle, scan) pairs; heading RMSE:
axis error modulo 180 deg over all matched vehicles / full heading error of vehicles faster than
1 m/s (\`tests/integration/tracker_eval.h\`). The logs of the table above:

\`\`\`sh
$B/tests/tracker-eval-scores WORK/runs/ITEM/run.lcm WORK/runs/ITEM/tracks_MODE.lcm
\`\`\`

$scores_md
EOF
  fi
  if [ -n "$boxes_cmd" ]; then
    cat <<EOF

## Box input: KITTI sequences tracked from detector boxes

Each sequence of the boxes layout (labels, PointRCNN car detections, estimated ego poses; no
point clouds) converted and tracked with \`--input-mode boxes\`; \`kitti_boxes_sum\` sums the
CLEAR MOT counts over the sequences.

\`\`\`sh
$boxes_cmd
\`\`\`

$(compare_table "$work/boxes.json")

### The KITTI 3-D criterion, summed over the sequences

The same tracks in the KITTI result format (\`vtrack-eval --kitti-out\`, the track score as the
score column; confirmed tracks, tentative ones in the frames a box measured them, and one
coasting frame after a miss: log_tools/README.md), scored by \`vtrack-eval-kitti\` inside the same run: class car, 3-D IoU >= 0.25,
the devkit's rules and AB3DMOT's score-threshold sweep over 40 recall points (percentages).
Prediction errors: \`vtrack-eval\`'s, over the sequences' matches (CLEAR MOT gate 2 m), all of
them, and split by the truth's own motion over the horizon: turning when its heading changes by
more than 0.1 rad/s times the horizon, else straight. cv is the constant-velocity reference
(heading held, no yaw rate); ism, vasm and mht the paper's models. AB3DMOT's figures are its
published car results from the same PointRCNN detections on the eleven other (validation)
training sequences, which are not in this folder; they are beside, not comparable one to one.

$(iou_table "$work/boxes.json")
EOF
  fi
  if [ -n "$bench_cmd" ]; then
    cat <<EOF

## Speed

CPU time is the process's CPU time (one thread unless a row says 2); other jobs on the machine inflate it, wall time more so:
compare figures within one run. What each program measures: [tests/bench/README.md](../tests/bench/README.md).

\`\`\`sh
$bench_cmd
\`\`\`

$(bench_table "$bench_json")

Studies of the threads, their pinning and the memory kept between sweeps, each with the commands that reproduce it: [docs/speed.md](speed.md).
EOF
  else
    cat <<EOF

## Speed

Not measured in this run: \`scripts/results.sh --bench\` adds the benchmarks (about 10 minutes).
Studies of the threads, their pinning and the memory kept between sweeps: [docs/speed.md](speed.md).
EOF
  fi
} >"$out.tmp"
mv "$out.tmp" "$out"
say "done in $((SECONDS - started)) s: $(rel "$out")"
