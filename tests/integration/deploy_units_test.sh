#!/usr/bin/env bash
# The systemd units of deploy/, as `cmake --install` writes them: installed into a
# scratch prefix (component `systemd`), every template variable filled in with that prefix, one
# unit per process, each restarted on failure and reading the LCM URL from /etc/vtrack/vtrack.env,
# whose URL has ttl=1. Each command line, with the environment file's values expanded as systemd
# does, is accepted by its program (run with --help). Then `systemd-analyze verify` (Debian's
# systemd package) must accept every unit without a word; where it is not installed the checks
# above stand alone and the test says so.
#
#   usage: deploy_units_test.sh BUILD_DIR
set -euo pipefail
build=${1:?usage: deploy_units_test.sh BUILD_DIR}
bin=${VTRACK_BIN_DIR:-$build/bin}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail=0
bad() { echo "FAIL: $*" >&2; fail=1; }

prefix=$tmp/prefix
cmake --install "$build" --prefix "$prefix" --component systemd > "$tmp/install.txt" 2>&1 \
  || { cat "$tmp/install.txt" >&2; echo "FAIL: cmake --install --component systemd" >&2; exit 1; }
dir=$prefix/share/vtrack/systemd
units=(vtrack-ladar-driver vtrack-ego-pose vtrack-tracker vtrack-render vtrack-logger)
for u in "${units[@]}"; do [ -f "$dir/$u.service" ] || bad "$u.service not installed in $dir"; done
[ -f "$dir/vtrack.env" ] || bad "vtrack.env not installed"
[ -f "$dir/README.md" ] || bad "README.md not installed"
[ $fail = 0 ] || exit 1

# The environment file: the URL with ttl=1, and every variable the units use is set.
env=$dir/vtrack.env
grep -qx 'LCM_DEFAULT_URL=udpm://239.255.76.67:7667?ttl=1' "$env" || bad "vtrack.env: LCM_DEFAULT_URL is not udpm://239.255.76.67:7667?ttl=1"
declare -A var=()
while IFS= read -r line; do
  [[ $line =~ ^[[:space:]]*(#|$) ]] && continue
  [[ $line =~ ^([A-Z_][A-Z0-9_]*)=(.*)$ ]] || { bad "vtrack.env: not KEY=VALUE: '$line'"; continue; }
  var[${BASH_REMATCH[1]}]=${BASH_REMATCH[2]}
done < "$env"

# Programs the units start, from the build (the scratch prefix has only the units).
mkdir -p "$prefix/bin"
for p in vtrack-ladar-driver vtrack-ego-pose vtrack-tracker vtrack-render; do
  [ -x "$bin/$p" ] || { echo "FAIL: $bin/$p is not built" >&2; exit 1; }
  ln -s "$bin/$p" "$prefix/bin/$p"
done
mkdir -p "$prefix/share/vtrack/config"
cp "${VTRACK_SOURCE_DIR:-$build/..}/config/tracker.yaml" "$prefix/share/vtrack/config/"

# systemd's expansion of an ExecStart line: $VAR alone as a word splits into words, ${VAR} in a
# word is replaced, %% is %, %S /var/lib, %C /var/cache.
expand() {
  local - w out=()
  set -f  # no globbing of the unit's words
  for w in $1; do
    if [[ $w =~ ^\$([A-Za-z_][A-Za-z0-9_]*)$ ]]; then
      [ -n "${var[${BASH_REMATCH[1]}]+x}" ] || bad "$2: \$${BASH_REMATCH[1]} is not set in vtrack.env"
      # shellcheck disable=SC2206
      out+=(${var[${BASH_REMATCH[1]}]:-})
      continue
    fi
    while [[ $w =~ \$\{([A-Za-z_][A-Za-z0-9_]*)\} ]]; do
      [ -n "${var[${BASH_REMATCH[1]}]+x}" ] || bad "$2: \${${BASH_REMATCH[1]}} is not set in vtrack.env"
      w=${w/"${BASH_REMATCH[0]}"/${var[${BASH_REMATCH[1]}]:-}}
    done
    w=${w//%S//var/lib}; w=${w//%C//var/cache}; w=${w//%%/%}
    out+=("$w")
  done
  printf '%s\n' "${out[@]}"
}

for u in "${units[@]}"; do
  f=$dir/$u.service
  grep -q '@' "$f" && bad "$u.service: template variable left: $(grep '@' "$f" | head -1)"
  grep -qx 'Restart=on-failure' "$f" || bad "$u.service: no Restart=on-failure"
  grep -qx 'EnvironmentFile=/etc/vtrack/vtrack.env' "$f" || bad "$u.service: no EnvironmentFile=/etc/vtrack/vtrack.env"
  for s in '\[Unit\]' '\[Service\]' '\[Install\]'; do grep -qx "$s" "$f" || bad "$u.service: no section $s"; done
  [ "$(grep -c '^ExecStart=' "$f")" = 1 ] || bad "$u.service: not exactly one ExecStart"
  exec_line=$(sed -n 's/^ExecStart=//p' "$f")
  mapfile -t argv < <(expand "$exec_line" "$u.service")
  case "$u" in
    vtrack-logger)
      [ "${argv[0]}" = "$(command -v lcm-logger)" ] || bad "$u.service: starts '${argv[0]}', not lcm-logger"
      # lcm-logger has no dry run: its options are checked against its own usage text.
      usage=$(lcm-logger -h 2>&1 || true)
      for a in "${argv[@]:1}"; do
        [[ $a == --* ]] || continue
        o=${a%%=*}
        grep -q -- "$o" <<< "$usage" || bad "$u.service: lcm-logger has no option $o"
      done
      [[ " ${argv[*]} " == *"--lcm-url=udpm://239.255.76.67:7667?ttl=1&recv_buf_size="* ]] \
        || bad "$u.service: the logger does not use the URL of vtrack.env with a receive buffer" ;;
    vtrack-render)
      # /bin/sh -c '...': the shell line names the renderer and passes the renderer's options.
      [ "${argv[0]}" = /bin/sh ] || bad "$u.service: expected /bin/sh -c"
      grep -q "$prefix/bin/vtrack-render" "$f" || bad "$u.service: does not start $prefix/bin/vtrack-render"
      # Run the shell line as systemd would hand it over, with the renderer replaced by its --help.
      line=$(sed -n "s/^ExecStart=\/bin\/sh -c '\(.*\)'$/\1/p" "$f" | sed 's/\$\$/$/g; s/%%/%/g')
      STATE_DIRECTORY=$tmp/state VTRACK_RENDER_ARGS="${var[VTRACK_RENDER_ARGS]}" \
        sh -c "${line} --help" > "$tmp/render_help.txt" 2>&1 || bad "$u.service: the command line fails: $(tail -3 "$tmp/render_help.txt")"
      ls -d "$tmp"/state/*/ > /dev/null 2>&1 || bad "$u.service: no per-start folder made" ;;
    *)
      [ "${argv[0]}" = "$prefix/bin/$u" ] || bad "$u.service: starts '${argv[0]}', not $prefix/bin/$u"
      # The tools parse every option before acting on --help: an unknown one fails here.
      "${argv[@]}" --help > "$tmp/$u.help.txt" 2>&1 || bad "$u.service: '${argv[*]} --help' fails: $(tail -3 "$tmp/$u.help.txt")" ;;
  esac
done

if command -v systemd-analyze > /dev/null 2>&1; then
  # systemd-analyze reports unknown keys and bad values on stderr even with exit status 0.
  if ! out=$(cd "$dir" && systemd-analyze verify ./*.service 2>&1) || [ -n "$out" ]; then
    bad "systemd-analyze verify: $out"
  else
    echo "systemd-analyze verify: ${#units[@]} units accepted"
  fi
else
  echo "systemd-analyze not installed (Debian package systemd): units checked by this script only"
fi
[ $fail = 0 ] && echo "deploy units: OK"
exit $fail
