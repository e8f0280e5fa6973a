#!/usr/bin/env bash
# `arcwheel process` on simulated float32 HDF5 scans as a user runs it: median wall time of 5 runs,
# peak resident memory (GNU time; the child process that reads the file counts too) against the
# input file, and the per-stage times of the median run (--timings).
#   1e6, 1e7: 22 mm of rim at 500 rpm with 10 us samples (the feed sets the sample count);
#   1e8: a long, fine scan, 400 kHz for four minutes (2000 turns over 22 mm).
# Usage: benchmarks/process_bench.sh [SAMPLES...]   (default: 1000000 10000000 100000000)
# ARCWHEEL_BINARY=path runs another build's arcwheel (build/cli/arcwheel by default): an older
# commit's, say, for a before-and-after the same hour.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
arcwheel="${ARCWHEEL_BINARY:-$root/build/cli/arcwheel}"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
sizes=("$@")
[ ${#sizes[@]} -eq 0 ] && sizes=(1000000 10000000 100000000)
echo "load before: $(cut -d' ' -f1-3 /proc/loadavg)"
for samples in "${sizes[@]}"; do
  if [ "$samples" -ge 100000000 ]; then
    period=2.5e-6
  else
    period=1e-5
  fi
  feed=$(python3 -c "print(22.0 / ($samples * $period) * 60.0)")
  "$arcwheel" simulate "$work/scan.h5" --sample-period-s "$period" --feed-mm-per-min "$feed" --noise-um 0.3 \
    --radial-harmonic 1:3:40 --radial-harmonic 3:0.8:15 --spike-rate 1e-5 >/dev/null
  size_kb=$(( $(stat -c %s "$work/scan.h5") / 1024 ))
  times=()
  peak_kb=0
  for run in 1 2 3 4 5; do
    /usr/bin/time -f "%e %M" -o "$work/time" "$arcwheel" process -q --timings "$work/scan.h5" -o "$work/out" \
      2> "$work/timings.$run"
    read -r seconds kb < "$work/time"
    times+=("$seconds")
    echo "$seconds $run" >> "$work/runs"
    (( kb > peak_kb )) && peak_kb=$kb
  done
  median=$(printf '%s\n' "${times[@]}" | sort -n | sed -n 3p)
  median_run=$(sort -n "$work/runs" | sed -n 3p | cut -d' ' -f2)
  rm -f "$work/runs"
  echo "samples $samples: median ${median} s of 5 runs ($(printf '%s ' "${times[@]}")), peak memory" \
    "$((peak_kb / 1024)) MiB = $(python3 -c "print(round($peak_kb / $size_kb, 2))") x the input" \
    "($((size_kb / 1024)) MiB); load after: $(cut -d' ' -f1-3 /proc/loadavg)"
  grep '^timing' "$work/timings.$median_run" | sed 's/^/  /'
done
