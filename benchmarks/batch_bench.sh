#!/usr/bin/env bash
# `arcwheel batch` at -j 1 and -j 2 on the same folder of simulated scans: median wall time of 3
# runs each (a fresh output folder every run, so nothing is reused), the CPU time of the batch and
# its children (GNU time counts waited-for children), and the load before and after.
#   Scans: the paper's settings (1.3e5 samples, float32 HDF5), each about 0.3 s to process.
# Usage: benchmarks/batch_bench.sh [SCANS]   (default 12)
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
arcwheel="$root/build/cli/arcwheel"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
count=${1:-12}
mkdir "$work/scans"
for i in $(seq "$count"); do
  "$arcwheel" simulate "$work/scans/wheel_$i.h5" --seed "$i" --noise-um 0.3 --radial-harmonic 1:3:40 >/dev/null
done
echo "$count scans; $(nproc) cores; load before: $(uptime | sed 's/.*load average: //')"
for jobs in 1 2; do
  walls=()
  for run in 1 2 3; do
    rm -rf "$work/out"
    /usr/bin/time -f "%e %U %S" -o "$work/time" "$arcwheel" batch "$work/scans" -o "$work/out" -j "$jobs" \
      >/dev/null 2>&1
    read -r wall user system <"$work/time"
    walls+=("$wall")
    echo "  -j $jobs run $run: ${wall} s wall, ${user}+${system} s cpu"
  done
  median=$(printf '%s\n' "${walls[@]}" | sort -n | sed -n 2p)
  echo "-j $jobs: median ${median} s of 3 ($(printf '%s ' "${walls[@]}")), $(python3 -c "print(round($count / $median, 2))") scans/s"
done
echo "load after: $(uptime | sed 's/.*load average: //')"
