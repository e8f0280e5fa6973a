#!/usr/bin/env bash
# The README's first command: installs only what the `arcwheel` binary needs, builds that one
# target (not the tests, benchmarks or the Python module) in build-demo/, and processes the shipped
# scan with a report decided against a shop tolerance file (ISO 14253-1). The time it takes on a fresh machine is in the README.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
"$root/scripts/install_deps.sh" --binary-only
cmake -S "$root" -B "$root/build-demo" -G Ninja -DCMAKE_BUILD_TYPE=Release -DARCWHEEL_BUILD_TESTS=OFF \
  -DARCWHEEL_BUILD_BENCHMARKS=OFF -DARCWHEEL_BUILD_PYTHON=OFF >/dev/null
cmake --build "$root/build-demo" --target arcwheel --parallel "$(nproc)"
out=${1:-"$root/out/demo"}
"$root/build-demo/cli/arcwheel" process "$root/testdata/paper_wheel_scan.h5" -o "$out" --report html,pdf \
  --tolerances "$root/testdata/paper_wheel_tolerances.json"
