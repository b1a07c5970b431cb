#!/usr/bin/env bash
# lcm-spy, started headless under Xvfb with the project's jar on its CLASSPATH, finds every
# vtrack message type. Debian's lcm-spy passes -Xincgc, which OpenJDK 17 refuses unless told to
# ignore unknown options (docs/design.md, section 8). Runs inside a private network namespace.
#   usage: lcm_spy_test.sh JAR LCMTYPES_DIR
set -euo pipefail
jar=$1; types_dir=$2
for tool in Xvfb lcm-spy java; do
  command -v "$tool" >/dev/null || { echo "FAIL: $tool is not installed (./vtrack.sh test installs it)"; exit 1; }
done
[ -f "$jar" ] || { echo "FAIL: jar $jar not built"; exit 1; }
expected=$(ls "$types_dir"/vtrack_*.lcm | wc -l)
work=$(mktemp -d)
display=:$(( 90 + RANDOM % 400 ))
Xvfb "$display" -screen 0 1024x768x24 -nolisten tcp >"$work/xvfb.log" 2>&1 &
xvfb=$!
spy=
cleanup() {
  [ -n "$spy" ] && kill "$spy" 2>/dev/null && wait "$spy" 2>/dev/null || true
  kill "$xvfb" 2>/dev/null && wait "$xvfb" 2>/dev/null || true
  rm -rf "$work"
}
trap cleanup EXIT
sleep 1
kill -0 "$xvfb" || { echo "FAIL: Xvfb did not start"; cat "$work/xvfb.log"; exit 1; }
DISPLAY=$display CLASSPATH=$jar JDK_JAVA_OPTIONS=-XX:+IgnoreUnrecognizedVMOptions \
  lcm-spy --lcm-url='udpm://239.255.76.67:7667?ttl=0' >"$work/spy.out" 2>&1 &
spy=$!
for _ in $(seq 1 100); do
  grep -q 'Found [0-9]* LCM types' "$work/spy.out" && break
  kill -0 "$spy" 2>/dev/null || break
  sleep 0.2
done
sleep 1
cat "$work/spy.out"
found=$(sed -n 's/.*Found \([0-9]*\) LCM types.*/\1/p' "$work/spy.out" | head -1)
kill -0 "$spy" 2>/dev/null || { echo "FAIL: lcm-spy exited"; exit 1; }
if [ "${found:-0}" -ne "$expected" ]; then
  echo "FAIL: lcm-spy found ${found:-no} LCM types, expected $expected"
  exit 1
fi
echo "PASS: lcm-spy found all $expected vtrack types and is running"
