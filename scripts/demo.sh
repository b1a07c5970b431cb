#!/usr/bin/env bash
# The demo (./vtrack.sh demo, which installs and builds first): the whole system live on an LCM
# bus inside a private network namespace (scripts/vtrack-netns: loopback only, nothing leaves the
# machine). lcm-logger, vtrack-ego-pose, vtrack-ladar-driver, vtrack-tracker and vtrack-render run
# for one full lap of the scenario (or the real KITTI sequence); then every process is stopped by
# its PID, the recording is scored by vtrack-eval, and a summary is printed.
#
#   usage: scripts/demo.sh BUILD_DIR [OPTIONS]      (./vtrack.sh demo [OPTIONS])
#
# Options:
#   --scenario NAME   scenario of config/scenarios/ or a YAML path [urban_intersection]
#   --kitti [DIR]     the real KITTI tracking sequence instead [../shared/data/kitti_tracking_0000]
#   --sequence N      KITTI sequence number [0000]
#   --sensor S        the scenario's sensor: single_plane | velodyne64 | a key of its `sensors`
#   --duration S      seconds of the scenario to run [its full length]
#   --mode M          tracker mode: mht | ism | vasm [mht]
#   --seed N          simulator seed [the scenario's]
#   --out DIR         where the log, video, PNGs and metrics go [BUILD_DIR/demo/<name>]
#   --record-scans    also record the scans, LADAR_SLICE and LADAR_SCAN (64-layer: ~1.7 GB per
#                     minute; by default every other channel is recorded, a few tens of MB)
#   --png-every N     a PNG every N rendered frames [50]
#   -h, --help        this help
#
# Exit status: 0 done; 1 a process or the evaluation failed; 2 bad option; 77 no private
# network namespace can be made here (needs root or unprivileged user namespaces).
set -euo pipefail

usage() { sed -n '2,25p' "$0" | sed 's/^# \{0,1\}//'; }
die() { echo "demo: $1" >&2; exit "${2:-1}"; }
say() { printf '\033[1m[demo]\033[0m %s\n' "$*" >&2; }

here=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)

[ $# -ge 1 ] || { usage >&2; exit 2; }
case "$1" in -h|--help) usage; exit 0 ;; esac
build_dir=$(cd "$1" 2>/dev/null && pwd) || die "build directory '$1' does not exist (run ./vtrack.sh demo)" 2
shift
bin=$build_dir/bin

# ---- options -------------------------------------------------------------------------------
scenario=urban_intersection kitti="" sequence=0000 sensor="" duration="" mode=mht seed=""
out="" record_scans=0 png_every=50 inside=0
need() { [ $# -ge 2 ] && [ -n "$2" ] || die "option $1 needs a value (see --help)" 2; }
while [ $# -gt 0 ]; do
  case "$1" in
    -h|--help) usage; exit 0 ;;
    --scenario) need "$@"; scenario=$2; shift 2 ;;
    --kitti)
      if [ $# -ge 2 ] && [ "${2#-}" = "$2" ]; then kitti=$2; shift 2
      else kitti=$here/../shared/data/kitti_tracking_0000; shift; fi ;;
    --sequence) need "$@"; sequence=$2; shift 2 ;;
    --sensor) need "$@"; sensor=$2; shift 2 ;;
    --duration) need "$@"; duration=$2; shift 2 ;;
    --mode) need "$@"; mode=$2; shift 2 ;;
    --seed) need "$@"; seed=$2; shift 2 ;;
    --out) need "$@"; out=$2; shift 2 ;;
    --record-scans) record_scans=1; shift ;;
    --png-every) need "$@"; png_every=$2; shift 2 ;;
    --inside-netns) inside=1; shift ;;   # internal: set when re-run inside the namespace
    *) die "unknown option '$1' (see --help)" 2 ;;
  esac
done

is_number() { [[ $1 =~ ^[0-9]+([.][0-9]+)?$ ]]; }
[ -z "$duration" ] || { is_number "$duration" && awk -v d="$duration" 'BEGIN{exit !(d>0)}'; } \
  || die "--duration '$duration' must be a positive number of seconds" 2
[[ $png_every =~ ^[1-9][0-9]*$ ]] || die "--png-every '$png_every' must be a positive integer" 2
[[ -z $seed || $seed =~ ^[0-9]+$ ]] || die "--seed '$seed' must be a non-negative integer" 2
case "$mode" in mht|ism|vasm) ;; *) die "--mode '$mode' must be mht, ism or vasm" 2 ;; esac
if [ -n "$kitti" ]; then
  [ -d "$kitti" ] || die "--kitti: '$kitti' is not a directory (the real sequence is in ../shared/data)" 2
  kitti=$(cd "$kitti" && pwd)
  [ -z "$sensor$seed$duration" ] || die "--sensor, --seed and --duration are for scenarios, not --kitti" 2
  name=kitti_$sequence
else
  if [ -f "$scenario" ]; then scenario=$(cd "$(dirname "$scenario")" && pwd)/$(basename "$scenario")
  elif [ ! -f "$here/config/scenarios/$scenario.yaml" ]; then
    die "--scenario '$scenario': no config/scenarios/$scenario.yaml and no such file (have: $(cd "$here/config/scenarios" && ls ./*.yaml | sed 's|^\./||; s|\.yaml$||' | tr '\n' ' '))" 2
  fi
  name=$(basename "$scenario" .yaml)${sensor:+_$sensor}
fi
out=${out:-$build_dir/demo/$name}
for t in vtrack-ladar-driver vtrack-ego-pose vtrack-tracker vtrack-render vtrack-eval vtrack-monitor; do
  [ -x "$bin/$t" ] || die "$bin/$t is not built (run ./vtrack.sh demo, which builds first)"
done
command -v lcm-logger >/dev/null || die "lcm-logger not found (Debian package liblcm-bin)"

# ---- outside the namespace: re-run this script inside a private one -------------------------
if [ $inside = 0 ]; then
  mkdir -p "$out" || die "cannot create --out '$out'"
  out=$(cd "$out" && pwd)
  args=(--out "$out" --mode "$mode" --png-every "$png_every")
  if [ -n "$kitti" ]; then args+=(--kitti "$kitti" --sequence "$sequence")
  else args+=(--scenario "$scenario"); fi
  [ -n "$sensor" ] && args+=(--sensor "$sensor")
  [ -n "$duration" ] && args+=(--duration "$duration")
  [ -n "$seed" ] && args+=(--seed "$seed")
  [ $record_scans = 1 ] && args+=(--record-scans)
  set +e
  "$here/scripts/vtrack-netns" "$0" "$build_dir" "${args[@]}" --inside-netns
  rc=$?
  set -e
  [ $rc = 77 ] && say "the demo needs a private network namespace (root, or unprivileged user namespaces): LCM multicast must not leave this machine"
  exit $rc
fi

# ---- inside the namespace --------------------------------------------------------------------
url="udpm://239.255.76.67:7667?ttl=0"
export LCM_DEFAULT_URL=$url
logs=$out/process_logs
rm -rf "$logs" "$out/png" "$out/plots"
mkdir -p "$logs"
log=$out/run.lcm video=$out/demo.mp4 pngs=$out/png metrics=$out/metrics.json
rm -f "$log" "$video" "$metrics" "$out/tracks.csv" "$out/summary.txt"

declare -A pid=()
stop_one() {  # NAME SIGNAL SECONDS: signal the process by PID, wait for it, SIGKILL after SECONDS
  local n=$1 sig=$2 limit=$3 p=${pid[$1]:-} i
  [ -n "$p" ] || return 0
  kill -"$sig" "$p" 2>/dev/null || true
  for ((i = 0; i < limit * 10; ++i)); do
    kill -0 "$p" 2>/dev/null || break
    sleep 0.1
  done
  if kill -0 "$p" 2>/dev/null; then
    say "$n (pid $p) did not stop on SIG$sig within $limit s: SIGKILL"
    kill -KILL "$p" 2>/dev/null || true
  fi
  local rc=0
  wait "$p" 2>/dev/null || rc=$?
  unset "pid[$n]"
  return $rc
}
cleanup() {
  local n
  for n in vtrack-ladar-driver vtrack-ego-pose vtrack-tracker vtrack-render lcm-logger; do
    [ -n "${pid[$n]:-}" ] && stop_one "$n" INT 10 || true
  done
}
interrupted() {
  trap - INT TERM
  echo >&2
  say "interrupted: stopping every process"
  cleanup
  say "stopped; partial outputs are in $out"
  exit 130
}
trap cleanup EXIT
trap interrupted INT TERM

start() {  # NAME COMMAND...: start in the background, output to process_logs/NAME.txt
  local n=$1; shift
  "$@" > "$logs/$n.txt" 2>&1 &
  pid[$n]=$!
}
wait_for() {  # NAME TEXT SECONDS: wait until the process has printed TEXT
  local i
  for ((i = 0; i < $3 * 10; ++i)); do
    grep -q -- "$2" "$logs/$1.txt" 2>/dev/null && return 0
    kill -0 "${pid[$1]}" 2>/dev/null || die "$1 exited early:$(echo; tail -5 "$logs/$1.txt")"
    sleep 0.1
  done
  return 1
}

# Sources: the same options for the driver and the ego-pose source.
if [ -n "$kitti" ]; then
  cache=${XDG_CACHE_HOME:-${HOME:-/tmp}/.cache}/vtrack
  src=(--kitti "$kitti" --sequence "$sequence" --cache-dir "$cache")
  say "KITTI sequence $sequence from $kitti (point clouds unpacked once into $cache)"
  # Unpack the packed point clouds before the live run (first time only, a few seconds).
  "$bin/vtrack-kitti2lcm" --kitti "$kitti" --sequence "$sequence" --cache-dir "$cache" \
    --num-frames 1 --out "$logs/unpack_check.lcm" --quiet > "$logs/unpack.txt" 2>&1 \
    || die "cannot read the KITTI sequence:$(echo; tail -5 "$logs/unpack.txt")"
  rm -f "$logs/unpack_check.lcm"
  lead_s=4
else
  src=(--scenario "$scenario")
  [ -n "$sensor" ] && src+=(--sensor "$sensor")
  [ -n "$duration" ] && src+=(--duration "$duration")
  [ -n "$seed" ] && src+=(--seed "$seed")
  # The lap's length, as the simulator itself reports it.
  "$bin/vtrack-sim-log" "${src[@]}" --describe > "$logs/describe.txt" 2>&1 \
    || die "the scenario or its options do not load:$(echo; tail -5 "$logs/describe.txt")" 2
  lead_s=3
fi

rmem=$(cat /proc/sys/net/core/rmem_max 2>/dev/null || echo 0)
if [ "$rmem" -lt 4194304 ]; then
  say "warning: net.core.rmem_max = $rmem bytes; 64-layer scans (2.8 MB) need 4194304 or more:"
  say "  sudo sysctl -w net.core.rmem_max=8388608   (otherwise scans are lost on the bus)"
fi

logger_args=(-q -f "--lcm-url=$url&recv_buf_size=8388608")
[ $record_scans = 1 ] || logger_args+=(-v -c 'LADAR_SCAN|LADAR_SLICE')
say "output: $out"
say "starting lcm-logger, vtrack-tracker ($mode), vtrack-render on $url (private network namespace)"
start lcm-logger lcm-logger "${logger_args[@]}" "$log"
start vtrack-tracker "$bin/vtrack-tracker" --mode "$mode" --debug
start vtrack-render "$bin/vtrack-render" --video "$video" --png-dir "$pngs" --png-every "$png_every"
wait_for vtrack-render "rendering live" 20 || die "vtrack-render did not start:$(echo; tail -5 "$logs/vtrack-render.txt")"

start_utime=$(( ($(date +%s) + lead_s) * 1000000 ))
say "starting vtrack-ego-pose and vtrack-ladar-driver (${src[*]}), the run starts at $(date -d @$((start_utime / 1000000)) +%T)"
start vtrack-ego-pose "$bin/vtrack-ego-pose" "${src[@]}" --start-utime "$start_utime" --laps 1
start vtrack-ladar-driver "$bin/vtrack-ladar-driver" "${src[@]}" --start-utime "$start_utime" --laps 1

# Progress while the lap runs: the driver's own progress line and the log's size.
t0=$(date +%s)
while kill -0 "${pid[vtrack-ladar-driver]}" 2>/dev/null; do
  sleep 5
  kill -0 "${pid[vtrack-ladar-driver]}" 2>/dev/null || break
  line=$(tr '\r' '\n' < "$logs/vtrack-ladar-driver.txt" | grep -v '^$' | tail -1 || true)
  size=$(du -m "$log" 2>/dev/null | cut -f1 || echo 0)
  say "$(( $(date +%s) - t0 )) s: ${line:-(waiting for the start)} | log ${size:-0} MB"
done
rc_driver=0; rc_ego=0
stop_one vtrack-ladar-driver INT 5 || rc_driver=$?
# The pose source finishes its lap within a fraction of a second of the driver.
for ((i = 0; i < 30; ++i)); do kill -0 "${pid[vtrack-ego-pose]}" 2>/dev/null || break; sleep 0.1; done
stop_one vtrack-ego-pose INT 5 || rc_ego=$?
sleep 1   # the tracker's last scans and the renderer's last frames
rc_tracker=0; rc_render=0; rc_logger=0
stop_one vtrack-tracker INT 10 || rc_tracker=$?
sleep 0.5
stop_one vtrack-render INT 60 || rc_render=$?
stop_one lcm-logger INT 10 || rc_logger=$?
wall=$(( $(date +%s) - t0 ))
failed=0
for n in driver ego tracker render logger; do
  v=rc_$n
  if [ "${!v}" != 0 ]; then
    failed=1
    say "$n exited with status ${!v}; its output is in $logs/"
  fi
done
[ $failed = 0 ] || die "a process failed"
say "all processes stopped ($wall s); evaluating $log"

# ---- evaluation ------------------------------------------------------------------------------
eval_args=("$log" --json "$metrics" --csv "$out/tracks.csv" --plots "$out/plots" -q)
if [ -n "$kitti" ]; then
  # As vtrack-compare does for KITTI: labels are half a sweep after the scan's utime, and only
  # camera 2's view (the labelled region) within 40 m is scored. Without the scans in the log
  # vtrack-eval cannot read the sweep (KITTI's is 100 ms: 0.05 s) nor the LADAR's mounting,
  # which it then takes at the body origin: exact for KITTI, whose body frame is the Velodyne's.
  offset=0.05
  [ $record_scans = 1 ] && offset=half-sweep
  eval_args+=(--truth-time-offset "$offset" --region-camera --kitti-calib "$kitti/calib/$sequence.txt" --region-range 40)
fi
"$bin/vtrack-eval" "${eval_args[@]}" > "$logs/vtrack-eval.txt" 2>&1 \
  || die "vtrack-eval failed:$(echo; tail -5 "$logs/vtrack-eval.txt")"
"$bin/vtrack-monitor" --input "$log" --width 0 > "$logs/monitor.txt" 2>&1 || true

# ---- summary ---------------------------------------------------------------------------------
json() {  # KEY: a top-level number of the metrics JSON ("-" for null or absent)
  local v
  v=$(tr -d '\n ' < "$metrics" | grep -o "\"$1\":[^,}]*" | head -1 | cut -d: -f2)
  [ -z "$v" ] || [ "$v" = null ] && echo - || echo "$v"
}
pred1=$(tr -d '\n ' < "$metrics" | grep -o '"prediction_error_m":{[^}]*}' | grep -o '"1":[^,}]*' | cut -d: -f2 || true)
rendered=$(grep -o '[0-9]* frames rendered, [0-9]* dropped' "$logs/vtrack-render.txt" | tail -1 || true)
# vtrack-monitor's table of the log: the vtrack channels with their message counts, and the
# tracker's last status line.
channels=$(awk '$2 ~ /_t$/ {printf "%s%s %s", sep, $1, $3; sep = ", "}' "$logs/monitor.txt")
status=$(awk '$1 == "TRACKER_STATUS" {sub(/.*scans /, "scans "); sub(/, decode.*/, ""); print}' "$logs/monitor.txt")
fmt() { awk -v v="$1" -v f="$2" 'BEGIN{ if (v == "-" || v == "") print "-"; else printf f, v }'; }
{
  echo
  echo "vtrack demo: $name, mode $mode, $wall s wall time (live, one lap)"
  echo
  printf '  %-34s %s\n' "scans with truth and tracks" "$(json scans)"
  printf '  %-34s %s\n' "messages recorded" "${channels:--}"
  printf '  %-34s %s\n' "tracker (last TRACKER_STATUS)" "${status:--}"
  printf '  %-34s %s\n' "renderer (live)" "${rendered:--}"
  printf '  %-34s %s\n' "truth vehicles scored" "$(json gt_objects)"
  printf '  %-34s %s\n' "true / false positives, misses" "$(json true_positives) / $(json false_positives), $(json false_negatives)"
  printf '  %-34s %s\n' "MOTA" "$(fmt "$(json mota)" '%.3f')"
  printf '  %-34s %s\n' "MOTP [m]" "$(fmt "$(json motp_m)" '%.3f')"
  printf '  %-34s %s\n' "HOTA" "$(fmt "$(json hota)" '%.3f')"
  printf '  %-34s %s\n' "identity switches" "$(json id_switches)"
  printf '  %-34s %s\n' "mostly tracked / lost" "$(json mostly_tracked) / $(json mostly_lost)"
  printf '  %-34s %s\n' "position RMSE [m]" "$(fmt "$(json position_rmse_m)" '%.3f')"
  printf '  %-34s %s\n' "heading RMSE [deg]" "$(fmt "$(json heading_rmse_deg)" '%.2f')"
  printf '  %-34s %s\n' "speed RMSE [m/s]" "$(fmt "$(json speed_rmse_mps)" '%.3f')"
  printf '  %-34s %s\n' "prediction error at 1 s [m]" "$(fmt "${pred1:--}" '%.3f')"
  printf '  %-34s %s\n' "NEES mean (3 = consistent)" "$(fmt "$(json nees_mean)" '%.2f')"
  echo
  echo "  log      $log$([ $record_scans = 1 ] || echo '  (every channel but LADAR_SCAN and LADAR_SLICE; --record-scans for all)')"
  echo "  video    $video"
  echo "  PNGs     $pngs/ ($(ls "$pngs" 2>/dev/null | wc -l) files)"
  echo "  metrics  $metrics (and tracks.csv, plots/)"
  echo "  outputs of each process: $logs/"
} | tee "$out/summary.txt"
