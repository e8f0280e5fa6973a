#!/usr/bin/env bash
# Builds the libFuzzer targets (clang, AddressSanitizer + UndefinedBehaviorSanitizer) and runs
# each for SECONDS (default 30) on the seeds in fuzz/seeds/. A crash leaves its input in
# fuzz/crashes/<target>/ and fails the script; turn it into a regression test.
#   scripts/fuzz.sh            # short run, as CI does
#   scripts/fuzz.sh 600        # ten minutes per target
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
seconds=${1:-30}
"$root/scripts/install_deps.sh"
CC=clang CXX=clang++ cmake -S "$root" -B "$root/build-fuzz" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DARCWHEEL_FUZZ=ON -DARCWHEEL_BUILD_TESTS=OFF -DARCWHEEL_BUILD_BENCHMARKS=OFF \
  "-DARCWHEEL_SANITIZE=address;undefined" >/dev/null
targets=(scan_csv_fuzzer scan_hdf5_fuzzer)
cmake --build "$root/build-fuzz" --parallel "$(nproc)" --target "${targets[@]}"
for target in "${targets[@]}"; do
  corpus=$(mktemp -d)
  cp "$root"/fuzz/seeds/* "$corpus"/
  mkdir -p "$root/fuzz/crashes/$target"
  echo "fuzz: $target for ${seconds} s"
  ASAN_OPTIONS=detect_leaks=1 "$root/build-fuzz/fuzz/$target" "$corpus" -max_total_time="$seconds" \
    -timeout=10 -rss_limit_mb=2048 -max_len=262144 -artifact_prefix="$root/fuzz/crashes/$target/" \
    -print_final_stats=1 2>&1 | grep -E "^(stat::number_of_executed_units|#[0-9]+ +DONE|==[0-9]+==ERROR|SUMMARY)" || true
  rm -rf "$corpus"
  if compgen -G "$root/fuzz/crashes/$target/*" >/dev/null; then
    echo "fuzz: $target found a failing input: $(ls "$root/fuzz/crashes/$target")" >&2
    exit 1
  fi
done
