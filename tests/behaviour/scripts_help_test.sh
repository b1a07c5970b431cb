#!/usr/bin/env bash
# Every tool in scripts/ answers --help: exit 0, a description on stdout, nothing run. In CI's
# environment the fitting scripts' libraries (python3-numpy, python3-sklearn) are not
# installed: their --help must not need them.
#   scripts_help_test.sh SOURCE_DIR
set -uo pipefail
src=${1:?usage: scripts_help_test.sh SOURCE_DIR}
failed=0 n=0
scratch=$(mktemp -d)  # the working directory of every call: a tool that wrote files would show
trap 'rm -rf "$scratch"' EXIT
for tool in "$src"/scripts/*; do
  [ -f "$tool" ] && [ -x "$tool" ] || continue
  n=$((n + 1))
  out=$(cd "$scratch" && timeout 30 "$tool" --help 2>&1)
  rc=$?
  lines=$(printf '%s\n' "$out" | grep -c '[A-Za-z]')
  if [ "$rc" -ne 0 ] || [ "$lines" -lt 2 ]; then
    echo "FAIL ${tool#"$src"/} --help: exit $rc, $lines lines of text:"
    printf '%s\n' "$out" | head -5 | sed 's/^/  /'
    failed=$((failed + 1))
  else
    echo "ok   ${tool#"$src"/} --help ($lines lines)"
  fi
done
[ "$n" -gt 0 ] || { echo "no tools in $src/scripts"; exit 1; }
echo "$((n - failed)) of $n tools answer --help"
[ "$failed" -eq 0 ]
