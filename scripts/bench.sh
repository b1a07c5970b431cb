#!/usr/bin/env bash
# Runs the tracker benchmarks (docs/design.md, section 9) and prints one table; writes the figures as JSON.
#
#   scripts/bench.sh BUILD_DIR [--json F] [--all] [--soak-minutes M] [--e2e-scans N] [--report-only]
#
#   BUILD_DIR          a Release build with the benchmarks (./vtrack.sh bench makes it)
#   --json F           where to write the figures (default: ./bench-results.json)
#   --all              also run the other benchmark programs (kitti, sim, eval, render)
#   --soak-minutes M   simulated length of the memory soak (default 10)
#   --e2e-scans N      scans published in each live latency run (default 150)
#   --report-only      run nothing: the table and JSON from the raw outputs of the last run
#
# Raw outputs (Google Benchmark JSON, logs) go to BUILD_DIR/bench-out/. Needs jq.
# A figure that cannot be measured here is null in the JSON, with the reason under "notes".
set -euo pipefail

here=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
usage() { sed -n '2,14p' "$0" | sed 's/^# \{0,1\}//'; }

[ $# -ge 1 ] || { usage; exit 2; }
case "$1" in -h|--help) usage; exit 0 ;; esac
build=$(cd "$1" && pwd) || { echo "bench.sh: no build directory '$1'" >&2; exit 2; }
shift
json_out=$PWD/bench-results.json
all=0
soak_minutes=10
e2e_scans=150
report_only=0
while [ $# -gt 0 ]; do
  case "$1" in
    --json) [ $# -ge 2 ] || { echo "bench.sh: --json needs a file" >&2; exit 2; }; json_out=$2; shift 2 ;;
    --all) all=1; shift ;;
    --soak-minutes) soak_minutes=${2:?}; shift 2 ;;
    --e2e-scans) e2e_scans=${2:?}; shift 2 ;;
    --report-only) report_only=1; shift ;;
    -h|--help) usage; exit 0 ;;
    *) echo "bench.sh: unknown option '$1'" >&2; usage >&2; exit 2 ;;
  esac
done
command -v jq >/dev/null || { echo "bench.sh: jq is needed (apt-get install jq)" >&2; exit 1; }
bench=$build/bench
out=$build/bench-out
mkdir -p "$out"
notes=()
log() { printf '\033[1m[bench]\033[0m %s\n' "$*" >&2; }

# Google Benchmark program -> $out/NAME.json (console output to $out/NAME.log).
run_gbench() {
  local name=$1; shift
  if [ ! -x "$bench/$name" ]; then
    log "$name is not built: skipped"
    notes+=("$name not built")
    return 0
  fi
  log "$name $*"
  local start=$SECONDS
  if ! "$bench/$name" --benchmark_out="$out/$name.json" --benchmark_out_format=json "$@" \
      >"$out/$name.log" 2>&1; then
    log "$name failed (see $out/$name.log)"
    notes+=("$name failed: see $out/$name.log")
    rm -f "$out/$name.json"
  fi
  log "  done in $((SECONDS - start)) s"
}

if [ $report_only = 0 ]; then
rm -f "$out"/*.json
run_gbench tracker_bench
run_gbench boxes_bench
run_gbench stages_bench
run_gbench models_bench
run_gbench fitting_bench
if [ -x "$bench/pcl_bench" ]; then
  run_gbench pcl_bench
else
  notes+=("pcl_cluster_speed_ratio: PCL not found at configure time (Debian libpcl-dev; ./vtrack.sh bench installs it)")
fi
if [ $all = 1 ]; then
  for b in kitti_bench sim_bench eval_bench render_bench; do run_gbench "$b"; done
fi

# Live latency over LCM in a private network namespace: sweeps sent whole (e2e) and in the
# driver's azimuth slices, each published when its last return is measured (e2e_sliced).
run_e2e() {  # run_e2e NAME SLICES
  local name=$1 slices=$2
  log "e2e_latency --slices $slices (private network namespace, $e2e_scans KITTI scans at 10 Hz)"
  set +e
  "$here/scripts/vtrack-netns" "$bench/e2e_latency" --bin-dir "$build/bin" --scans "$e2e_scans" \
    --slices "$slices" --json "$out/$name.json" --tracker-log "$out/${name}_tracker.log" >"$out/$name.log" 2>&1
  local rc=$?
  set -e
  if [ $rc = 77 ]; then
    notes+=("$name latency: no private network namespace here (scripts/vtrack-netns exit 77; needs root/unshare)")
    return 77
  elif [ $rc != 0 ]; then
    notes+=("$name latency failed (exit $rc): see $out/$name.log")
  fi
  tail -n 1 "$out/$name.log" >&2 || true
}
if [ -x "$bench/e2e_latency" ]; then
  if run_e2e e2e 0; then
    run_e2e e2e_sliced auto || true
  fi
else
  notes+=("e2e_latency not built")
fi

# Memory over a long simulated run.
if [ -x "$bench/tracker_soak" ]; then
  log "tracker_soak ($soak_minutes simulated minutes of stress)"
  if ! "$bench/tracker_soak" --minutes "$soak_minutes" --json "$out/soak.json" >"$out/soak.log" 2>&1; then
    notes+=("tracker_soak failed: see $out/soak.log")
  fi
  tail -n 1 "$out/soak.log" >&2 || true
else
  notes+=("tracker_soak not built")
fi
fi  # report_only
if [ $report_only = 1 ]; then
  for f in tracker_bench boxes_bench stages_bench models_bench fitting_bench pcl_bench e2e e2e_sliced soak; do
    [ -s "$out/$f.json" ] || notes+=("no $f output in $out (not built, skipped or failed: see its .log)")
  done
fi

# ---- aggregate -------------------------------------------------------------------------------
gb() {  # gb FILE: the benchmarks array of a Google Benchmark JSON, [] if missing
  if [ -s "$out/$1.json" ]; then jq '.benchmarks' "$out/$1.json"; else echo '[]'; fi
}
side() { if [ -s "$out/$1.json" ]; then cat "$out/$1.json"; else echo '{}'; fi; }
notes_json=$(printf '%s\n' "${notes[@]+"${notes[@]}"}" | jq -R . | jq -s 'map(select(length > 0))')

jq -n \
  --argjson tb "$(gb tracker_bench)" --argjson sb "$(gb stages_bench)" --argjson xb "$(gb boxes_bench)" \
  --argjson mb "$(gb models_bench)" --argjson fb "$(gb fitting_bench)" \
  --argjson pb "$(gb pcl_bench)" --argjson e2e "$(side e2e)" --argjson e2es "$(side e2e_sliced)" --argjson soak "$(side soak)" \
  --argjson notes "$notes_json" --arg host "$(uname -n)" --arg cpu "$(nproc) cores" \
  --arg commit "$(git -C "$here" rev-parse --short HEAD 2>/dev/null || echo unknown)" '
  # first successful run of a benchmark (one that skipped with an error, e.g. no KITTI data, is absent)
  def bm($arr; $prefix): [$arr[] | select(.name | startswith($prefix)) | select(.error_occurred != true)] | first;
  # CPU time per iteration in ms; for the manual-time benchmarks the manual time (thread CPU time).
  def ms($b): if $b == null then null
              else ((if ($b.name | test("manual_time")) then $b.real_time else $b.cpu_time end)
                    * (if $b.time_unit == "ns" then 1e-6 elif $b.time_unit == "us" then 1e-3
                       elif $b.time_unit == "s" then 1e3 else 1 end)) end;
  def slope($pts): if ($pts | length) < 2 then null else
      ($pts | map(.[0]) | add / length) as $mx | ($pts | map(.[1]) | add / length) as $my |
      (($pts | map((.[0] - $mx) * (.[1] - $my)) | add) / ($pts | map((.[0] - $mx) * (.[0] - $mx)) | add)) end;
  def scaling($prefix):
      [$tb[] | select(.name | startswith($prefix)) | select(.error_occurred != true)
       | {n: (.name | split("/")[1] | tonumber), ms: .median_ms}];
  bm($tb; "BM_TrackerScan_Kitti/") as $k | bm($tb; "BM_TrackerScan_Stress/") as $s |
  bm($tb; "BM_TrackerScan_Kitti_2Threads/") as $k2 |
  bm($tb; "BM_TrackerScan_Kitti_2Threads_10Hz/") as $k10 |
  bm($tb; "BM_TrackerScan_Kitti_2Threads_10Hz_Unpinned/") as $k10u |
  bm($pb; "BM_Pipeline_PclVoxelEuclidean") as $ppcl | bm($pb; "BM_Pipeline_VtrackTracker") as $pvt |
  bm($tb; "BM_TrackerScan_Fig4") as $f | bm($tb; "BM_CopyFloor_Kitti") as $c |
  scaling("BM_PointsScaling/") as $pts | scaling("BM_ObjectsScaling/") as $objs |
  bm($pb; "BM_Segmentation_Grid") as $grid | bm($pb; "BM_Segmentation_PclEuclidean") as $pcl |
  {
    commit: $commit, host: $host, cpu: $cpu,
    kitti_ms_per_scan_median: $k.median_ms, kitti_ms_per_scan_p99: $k.p99_ms,
    kitti_wall_ms_per_scan_median: $k.wall_median_ms, kitti_points_per_scan: $k.points_per_scan,
    kitti_tracks_per_scan: $k.tracks_per_scan,
    kitti_2threads_cpu_ms_median: $k2.median_ms, kitti_2threads_wall_ms_median: $k2.wall_median_ms,
    kitti_2threads_wall_ms_p99: $k2.wall_p99_ms,
    kitti_2threads_10hz_wall_ms_median: $k10.wall_median_ms, kitti_2threads_10hz_wall_ms_p99: $k10.wall_p99_ms,
    kitti_2threads_10hz_unpinned_wall_ms_median: $k10u.wall_median_ms,
    kitti_2threads_10hz_unpinned_wall_ms_p99: $k10u.wall_p99_ms,
    kitti_stage_ms: (if $k == null then null else
      {preprocess: $k.pre_ms, segmentation: $k.seg_ms, association: $k.assoc_ms, updates_and_rest: $k.rest_ms,
       updates: $k.upd_ms, new_tracks: $k.new_ms, life_cycle: $k.life_ms} end),
    stress_ms_per_scan_median: $s.median_ms, stress_ms_per_scan_p99: $s.p99_ms,
    stress_points_per_scan: $s.points_per_scan, stress_tracks_per_scan: $s.tracks_per_scan,
    stress_stage_ms: (if $s == null then null else
      {preprocess: $s.pre_ms, segmentation: $s.seg_ms, association: $s.assoc_ms, updates_and_rest: $s.rest_ms,
       updates: $s.upd_ms, new_tracks: $s.new_ms, life_cycle: $s.life_ms} end),
    fig4_ms_per_scan_median: $f.median_ms,
    copy_floor_ms_per_scan: $c.median_ms,
    copy_floor_ratio: (if $k == null or $c == null then null else $k.median_ms / $c.median_ms end),
    points_scaling: $pts,
    points_growth_exponent: slope([$pts[] | [(.n | log), (.ms | log)]]),
    objects_scaling: $objs,
    objects_growth_exponent: slope([$objs[] | [(.n | log), (.ms | log)]]),
    pcl_cluster_speed_ratio: (if $pcl == null or $grid == null then null else ms($pcl) / ms($grid) end),
    pcl_cluster_ms: ms($pcl), grid_cluster_ms: ms($grid),
    pcl_adjusted_rand_index: $pcl.adjusted_rand, pcl_segments_matched: $pcl.segments_matched,
    pcl_pipeline_ms: ms($ppcl), vtrack_pipeline_ms: ms($pvt),
    pcl_pipeline_ratio: (if $ppcl == null or $pvt == null then null else ms($ppcl) / ms($pvt) end),
    e2e_latency_ms_median: $e2e.e2e_latency_ms_median, e2e_latency_ms_p99: $e2e.e2e_latency_ms_p99,
    e2e_latency_ms_max: $e2e.e2e_latency_ms_max, e2e_lost: $e2e.e2e_lost,
    e2e_tracker_ms_median: $e2e.e2e_tracker_ms_median, e2e_tracker_ms_p99: $e2e.e2e_tracker_ms_p99,
    e2e_sliced_latency_ms_median: $e2es.e2e_latency_ms_median, e2e_sliced_latency_ms_p99: $e2es.e2e_latency_ms_p99,
    e2e_sliced_latency_ms_max: $e2es.e2e_latency_ms_max, e2e_sliced_lost: $e2es.e2e_lost,
    e2e_sliced_slices_per_scan: $e2es.e2e_slices_per_scan,
    e2e_sliced_tracker_ms_median: $e2es.e2e_tracker_ms_median, e2e_sliced_tracker_ms_p99: $e2es.e2e_tracker_ms_p99,
    rss_growth_pct: $soak.rss_growth_pct, rss_growth_second_half_pct: $soak.rss_growth_second_half_pct,
    rss_start_mb: $soak.rss_start_mb, rss_half_mb: $soak.rss_half_mb,
    rss_end_mb: $soak.rss_end_mb, rss_peak_mb: $soak.rss_peak_mb,
    heap_start_mb: $soak.heap_start_mb, heap_end_mb: $soak.heap_end_mb, heap_peak_mb: $soak.heap_peak_mb,
    boxes_frames_per_s: ([$xb[] | select(.error_occurred != true)
                          | {key: (.name | sub("^BM_BoxesSequence/"; "")), value: .frames_per_s}] | from_entries),
    boxes_frames: (bm($xb; "BM_BoxesSequence").frames),
    stages_ms: ([$sb[] | {key: (.name | sub("^BM_"; "")), value: ms(.)}] | from_entries),
    models_us: ([$mb[] | {key: (.name | sub("^BM_"; "")), value: (ms(.) * 1000)}] | from_entries),
    fitting_us: ([$fb[] | {key: (.name | sub("^BM_"; "")), value: (ms(.) * 1000)}] | from_entries),
    notes: $notes
  }' >"$json_out"

# ---- the table ---------------------------------------------------------------------------------
jq -r '
  def f($x; $d): if $x == null then "n/a" else ($x * pow(10; $d) | round / pow(10; $d) | tostring) end;
  def ok($c): if $c == null then "" elif $c then "met" else "MISSED" end;
  def lt($x; $t): if $x == null then null else $x <= $t end;
  ["measure", "value", "target", ""],
  ["KITTI 0000 ms/scan (CPU, one thread) median", f(.kitti_ms_per_scan_median; 2), "<= 6", ok(lt(.kitti_ms_per_scan_median; 6))],
  ["KITTI 0000 ms/scan p99", f(.kitti_ms_per_scan_p99; 2), "<= 10", ok(lt(.kitti_ms_per_scan_p99; 10))],
  ["KITTI wall ms/scan median (shared machine)", f(.kitti_wall_ms_per_scan_median; 2), "", ""],
  ["KITTI 2 threads: CPU (both) median / wall median / wall p99",
    "\(f(.kitti_2threads_cpu_ms_median; 2)) / \(f(.kitti_2threads_wall_ms_median; 2)) / \(f(.kitti_2threads_wall_ms_p99; 2))", "", ""],
  ["KITTI 2 threads, scans 100 ms apart: wall median / p99, pinned (shipped) | unpinned",
    "\(f(.kitti_2threads_10hz_wall_ms_median; 2)) / \(f(.kitti_2threads_10hz_wall_ms_p99; 2)) | \(f(.kitti_2threads_10hz_unpinned_wall_ms_median; 2)) / \(f(.kitti_2threads_10hz_unpinned_wall_ms_p99; 2))", "", ""],
  ["KITTI returns / tracks per scan", "\(f(.kitti_points_per_scan; 0)) / \(f(.kitti_tracks_per_scan; 0))", "", ""],
  ["KITTI stages ms: preprocess / segment + profile / associate / updates / new tracks / life cycle + report",
    (if .kitti_stage_ms == null then "n/a" else "\(f(.kitti_stage_ms.preprocess; 2)) / \(f(.kitti_stage_ms.segmentation; 2)) / \(f(.kitti_stage_ms.association; 2)) / \(f(.kitti_stage_ms.updates; 2)) / \(f(.kitti_stage_ms.new_tracks; 2)) / \(f(.kitti_stage_ms.life_cycle; 2))" end), "", ""],
  ["stress ms/scan median / p99", "\(f(.stress_ms_per_scan_median; 2)) / \(f(.stress_ms_per_scan_p99; 2))", "<= 6", ok(lt(.stress_ms_per_scan_median; 6))],
  ["stress stages ms: preprocess / segment + profile / associate / updates / new tracks / life cycle + report",
    (if .stress_stage_ms == null then "n/a" else "\(f(.stress_stage_ms.preprocess; 2)) / \(f(.stress_stage_ms.segmentation; 2)) / \(f(.stress_stage_ms.association; 2)) / \(f(.stress_stage_ms.updates; 2)) / \(f(.stress_stage_ms.new_tracks; 2)) / \(f(.stress_stage_ms.life_cycle; 2))" end), "", ""],
  ["paper_fig4_turn ms/scan median", f(.fig4_ms_per_scan_median; 3), "", ""],
  ["boxes only, KITTI 0020 frames/s (CPU) " + (.boxes_frames_per_s | keys_unsorted | join(" / ")),
    (.boxes_frames_per_s | to_entries | map(f(.value; 0)) | join(" / ")), ">= 2000 (mht)",
    ok(if .boxes_frames_per_s.mht == null then null else .boxes_frames_per_s.mht >= 2000 end)],
  ["copy floor ms/scan (KITTI point arrays)", f(.copy_floor_ms_per_scan; 3), "", ""],
  ["tracker / copy floor", f(.copy_floor_ratio; 1), "<= 10", ok(lt(.copy_floor_ratio; 10))],
  ["points 10k..1M: ms/scan", (.points_scaling | map("\(.n / 1000)k:\(f(.ms; 1))") | join(" ")), "", ""],
  ["points growth exponent", f(.points_growth_exponent; 2), "~1", ok(lt(.points_growth_exponent; 1.2))],
  ["objects 10..1000: ms/scan", (.objects_scaling | map("\(.n):\(f(.ms; 1))") | join(" ")), "", ""],
  ["objects growth exponent", f(.objects_growth_exponent; 2), "", ""],
  ["PCL Euclidean / grid segmentation time", f(.pcl_cluster_speed_ratio; 1), "> 1", ok(if .pcl_cluster_speed_ratio == null then null else .pcl_cluster_speed_ratio > 1 end)],
  ["  PCL ms / grid ms; adjusted Rand; segments matched", "\(f(.pcl_cluster_ms; 2)) / \(f(.grid_cluster_ms; 2)); \(f(.pcl_adjusted_rand_index; 3)); \(f(.pcl_segments_matched; 3))", "", ""],
  ["PCL VoxelGrid+Euclidean / vtrack whole tracker, per sweep", f(.pcl_pipeline_ratio; 1), "", ""],
  ["  PCL pipeline ms / vtrack tracker ms (KITTI, raw sweeps)", "\(f(.pcl_pipeline_ms; 2)) / \(f(.vtrack_pipeline_ms; 2))", "", ""],
  ["e2e latency ms median / p99 (LCM, 10 Hz, KITTI, whole sweeps)", "\(f(.e2e_latency_ms_median; 2)) / \(f(.e2e_latency_ms_p99; 2))", "p99 < 20", ok(lt(.e2e_latency_ms_p99; 20))],
  ["  of which in the tracker (sweep decoded to publish) median / p99", "\(f(.e2e_tracker_ms_median; 2)) / \(f(.e2e_tracker_ms_p99; 2))", "", ""],
  ["e2e latency ms median / p99 (the same, sweeps in \(f(.e2e_sliced_slices_per_scan; 1)) slices)", "\(f(.e2e_sliced_latency_ms_median; 2)) / \(f(.e2e_sliced_latency_ms_p99; 2))", "p99 < 20", ok(lt(.e2e_sliced_latency_ms_p99; 20))],
  ["  of which in the tracker (sweep put together to publish) median / p99", "\(f(.e2e_sliced_tracker_ms_median; 2)) / \(f(.e2e_sliced_tracker_ms_p99; 2))", "", ""],
  ["RSS MB start / half time / end / peak (10 min stress)", "\(f(.rss_start_mb; 1)) / \(f(.rss_half_mb; 1)) / \(f(.rss_end_mb; 1)) / \(f(.rss_peak_mb; 1))", "", ""],
  ["RSS growth % from minute 1 / over the second half (a leak)", "\(f(.rss_growth_pct; 2)) / \(f(.rss_growth_second_half_pct; 2))", "~0", ok(if .rss_growth_second_half_pct == null then null else .rss_growth_second_half_pct < 2 end)],
  (.stages_ms | to_entries[] | ["stage: \(.key) ms", f(.value; 3), "", ""]),
  (.models_us | to_entries[] | select(.key | test("PredictUpdate")) | ["EKF: \(.key) us", f(.value; 2), "", ""]),
  (.fitting_us | to_entries[] | ["fit: \(.key) us", f(.value; 1), "", ""]),
  (.notes[] | ["note", ., "", ""])
  | @tsv' "$json_out" | awk -F'\t' '{ printf "%-66s %-44s %-9s %s\n", $1, $2, $3, $4 }'
log "figures written to $json_out (raw outputs in $out)"
