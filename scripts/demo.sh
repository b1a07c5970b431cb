#!/usr/bin/env bash
# The demo (./vtrack.sh demo): until the full pipeline lands it shows what exists: the message
# types on a real LCM bus inside a private network namespace.
set -euo pipefail
build_dir=$1; shift
echo "vtrack demo: the pipeline (driver, tracker, renderer, evaluator) is not built yet."
echo "What exists: message types ($build_dir/lcmtypes/include/vtrack) and the Java jar for lcm-spy."
ls "$build_dir"/lcmtypes/include/vtrack
