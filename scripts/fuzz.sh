#!/usr/bin/env bash
# Builds the libFuzzer targets (clang, AddressSanitizer + UndefinedBehaviorSanitizer) and runs each
# for SECONDS (default 20) on its seeds in fuzz/seeds/<target>/. A crash, leak, hang or sanitizer
# report leaves its input in fuzz/crashes/<target>/ and fails the script; turn it into a regression
# test in tests/.
# The build is preset fuzz (build-fuzz/): coverage feedback from every library, for runs that are
# to find something. CI passes FUZZ_PRESET=asan: the sanitizer suite's build, whose libraries carry
# no coverage instrumentation, so there the targets replay and mutate their seeds, little guided.
#   scripts/fuzz.sh                         # every target, 20 s each
#   scripts/fuzz.sh 600                     # ten minutes per target
#   scripts/fuzz.sh 600 scan_hdf5_fuzzer    # one target
#   FUZZ_JOBS=3 scripts/fuzz.sh 600         # three targets at a time
#   FUZZ_BUILD=0 scripts/fuzz.sh 600        # the binaries already in build-fuzz/fuzz/
#   FUZZ_PRESET=asan scripts/fuzz.sh 20     # the targets of the sanitizer suite's build (CI)
#   FUZZ_SEED=1 scripts/fuzz.sh 20          # the same mutations every run (CI: a gate, not a search)
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
seconds=${1:-20}
shift || true
if (($# > 0)); then
  targets=("$@")
else
  # zygo_datx_fuzzer reads each input as the command line does, first in a child process that
  # libhdf5 1.10.8 itself may crash (docs/known_issues.md): about ten inputs a second, and a
  # sanitizer report from each such child. Left out of the default (CI) set; run it by name.
  mapfile -t targets < <(cd "$root/fuzz" && ls ./*_fuzzer.cc | sed -e 's|^\./||' -e 's|\.cc$||' | grep -v '^zygo_datx_fuzzer$')
fi
jobs=${FUZZ_JOBS:-1}
preset=${FUZZ_PRESET:-fuzz}
case $preset in
  fuzz) build_dir=$root/build-fuzz ;;
  asan) build_dir=$root/build-asan ;;
  *) echo "fuzz: FUZZ_PRESET must be fuzz or asan, not '$preset'" >&2; exit 1 ;;
esac
cd "$root"
if [[ ${FUZZ_BUILD:-1} != 0 ]]; then
  "$root/scripts/install_deps.sh"
  cmake --preset "$preset" >/dev/null
  cmake --build --preset "$preset" --parallel "$(nproc)" --target "${targets[@]}"
fi
# libhdf5 itself may ask for gigabytes while opening a damaged file (H5Fopen reading an object
# header): such a request returns NULL, which the library reports as a failed open, instead of
# counting as our out-of-memory. Our own allocations are bounded before they are made, and the
# resident-memory limit still stops any run that really uses more than 2 GB.
export ASAN_OPTIONS=allocator_may_return_null=1:max_allocation_size_mb=2048:detect_leaks=1:suppressions="$root/scripts/asan.supp"
export LSAN_OPTIONS=suppressions="$root/scripts/lsan.supp"
export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1

# Runs one target; prints one line; exits non-zero if it found anything.
fuzz_one() {
  local target=$1 corpus work crashes status=0 runs
  corpus=$(mktemp -d)
  work=$(mktemp -d)
  cp "$root/fuzz/seeds/$target"/* "$corpus"/
  crashes="$root/fuzz/crashes/$target"
  mkdir -p "$crashes"
  TMPDIR=$work "$build_dir/fuzz/$target" "$corpus" -max_total_time="$seconds" -timeout=10 \
    -rss_limit_mb=2048 -malloc_limit_mb=65536 -max_len=262144 -artifact_prefix="$crashes/" -print_final_stats=1 \
    -seed="${FUZZ_SEED:-0}" \
    >"$work/log" 2>&1 || status=$?
  runs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$work/log")
  echo "fuzz: $target: ${seconds} s, ${runs:-?} executions, exit $status"
  if ((status != 0)) || compgen -G "$crashes/*" >/dev/null; then
    # libhdf5's refused giant allocations print a warning each: leave them out to show the finding.
    grep -v "failed to allocate" "$work/log" | grep -E "ERROR|SUMMARY|==[0-9]+==|#[0-9]+ 0x|Test unit written" |
      head -40 >&2 || true
    echo "fuzz: $target failed; inputs kept in $crashes" >&2
    rm -rf "$corpus" "$work"
    return 1
  fi
  rmdir "$crashes" 2>/dev/null || true
  rm -rf "$corpus" "$work"
}

failed=0
running=0
for target in "${targets[@]}"; do
  fuzz_one "$target" &
  running=$((running + 1))
  if ((running >= jobs)); then
    wait -n || failed=1
    running=$((running - 1))
  fi
done
while ((running > 0)); do
  wait -n || failed=1
  running=$((running - 1))
done
exit "$failed"
