#!/usr/bin/env bash
# The whole test suite built with AddressSanitizer and UndefinedBehaviorSanitizer (preset asan:
# clang; UBSan's arithmetic checks, its pointer checks left to ASan, see cmake/ArcwheelHelpers.cmake;
# the fuzz targets are in the same build, but no library carries the fuzzer's coverage
# instrumentation, which would slow every test several times over).
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
"$root/scripts/install_deps.sh"
cd "$root"
cmake --preset asan -DARCWHEEL_WERROR="${ARCWHEEL_WERROR:-OFF}" >/dev/null
cmake --build --preset asan --parallel "$(nproc)"
# A damaged HDF5 header may make the library ask for an absurd buffer; like glibc, return NULL
# (HDF5 reports the failure) instead of aborting. fontconfig's caches are not our leaks.
# A freed block stays poisoned until 16 MB more have been freed (the default quarantine holds
# 256 MB): a use soon after the free is still caught, a use after 16 MB of other frees no longer.
# Behind the large quarantine every allocation faulted in fresh pages: the suite took 382 s
# (245 s of it system time) against 327 s (185 s) with 16 MB (2026-12-07, 2 cores).
export ASAN_OPTIONS=allocator_may_return_null=1:detect_leaks=1:quarantine_size_mb=16:suppressions="$root/scripts/asan.supp"
export LSAN_OPTIONS=suppressions="$root/scripts/lsan.supp"
export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
# Cases that check a number on a large problem and run only code that smaller cases run too are
# left to the Release suite: the 1e7-sample cases of tests/hard_scans_test (the mean radius's
# z-score at that size; the 1e6 cases run the same code), and the three dwell solves over a
# 1 mm map of the 100 mm disc (RecoversAKnownDwell, the least-dwell cases and the shaping cases
# run the same solver on the Gaussian footprint, PredictsTheRemovalOfAnOffsetEllipticFootprint on
# a measured one, FollowsTheArchimedeanSpiral the spiral). Here they cost 160 of dwell_test's 270
# CPU-s (measured 2026-12-02). Likewise the wheel model's statistics over many noise draws
# (WheelModelStatistics; its noise-free and single-draw cases run the same fit). The history of
# eight simulated and processed scans (HistoryCommand.ReportsTheKnownWear*; the comparison of
# three scans and the history's refusals and building blocks still run). And the second scan that
# tests/regenerate_test processes for --wheel-profile model (WheelProfileModel; the Regenerate
# cases run process, toolpath and polish on the first). And the 1e6-sample scans that
# tests/same_results_test processes (SameResults.ShippedScan still runs). And the interrupted
# batch of tests/batch_test (four 3e5-sample scans: 11 of the file's 31 s here under ASan, load 7;
# the child's own unwinding on a signal runs in tests/fault_test, the batch's other cases run).
# And the 300 paper-wheel scans of tests/all_sample_accuracy_test (the statistics over seeds;
# every process run, tests/same_results_test's shipped scan among them, runs the same fits), and
# the 24 scans of tests/uncertainty_coverage_test (42 s here, 2026-12-03; uncertainty/'s own tests
# run the same estimators, and every process run the same budget), and the 2 x 12 scans of
# tests/characteristics_coverage_test (164 s here under the sanitizers, a sixth of the suite, 2026-12-05;
# characteristics/'s own tests run the same operators, and every process run evaluates them).
export GTEST_FILTER="${GTEST_FILTER:--*N1e7*:*AllSampleAccuracy.*:SolveDwell.CutsTheResidualRmsTenfold*:SolveDwell.AMeasuredGaussian*:SpiralPath.CarriesADwell*:WheelModelStatistics.*:HistoryCommand.ReportsTheKnownWear*:WheelProfileModel.*:SameResults.SimulatedN1e6*:Batch.AnInterruptedBatch*:UncertaintyCoverage.*:CharacteristicsCoverage.*}"
ctest --preset asan --parallel "$(nproc)" "$@"
