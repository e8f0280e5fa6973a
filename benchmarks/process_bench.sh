#!/usr/bin/env bash
# `arcwheel process` on simulated float32 HDF5 scans of 1e6 and 1e7 samples, as a user runs it:
# median wall time of 5 runs and peak resident memory (GNU time), against the input file size.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
arcwheel="$root/build/cli/arcwheel"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
for samples in 1000000 10000000; do
  # 22 mm of rim at 500 rpm with 10 us samples: the feed sets the sample count.
  feed=$(python3 -c "print(22.0 / ($samples * 1e-5) * 60.0)")
  "$arcwheel" simulate "$work/scan.h5" --sample-period-s 1e-5 --feed-mm-per-min "$feed" --noise-um 0.3 \
    --radial-harmonic 1:3:40 --radial-harmonic 3:0.8:15 --spike-rate 1e-5 >/dev/null
  size_kb=$(( $(stat -c %s "$work/scan.h5") / 1024 ))
  times=()
  peak_kb=0
  for run in 1 2 3 4 5; do
    /usr/bin/time -f "%e %M" -o "$work/time" "$arcwheel" process -q "$work/scan.h5" -o "$work/out"
    read -r seconds kb < "$work/time"
    times+=("$seconds")
    (( kb > peak_kb )) && peak_kb=$kb
  done
  median=$(printf '%s\n' "${times[@]}" | sort -n | sed -n 3p)
  echo "samples $samples: median ${median} s of 5 runs ($(printf '%s ' "${times[@]}")), peak memory $((peak_kb / 1024)) MiB, input $((size_kb / 1024)) MiB"
done
