#!/usr/bin/env bash
# The README's first command: installs what is missing, builds, and processes the shipped scan.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
"$root/scripts/build.sh"
out=${1:-"$root/out/demo"}
"$root/build/cli/arcwheel" process "$root/testdata/paper_wheel_scan.h5" -o "$out" --report html,pdf
