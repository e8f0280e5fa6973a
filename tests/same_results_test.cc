// `arcwheel process` gives the same numbers after a change made for speed or memory: every number
// of summary.json for the shipped scan and for simulated 1e6- and 1e7-sample scans, against the
// summary.json that the version before the read-once, float32 and despiker changes wrote
// (testdata/regression/, made as testdata/README.md says).
//
// The `model` section is left out: the wheel model's knot choice was fixed since (its linearised
// coarser fits lost digits to cancellation, which chose 4 radius knots for a constant-radius
// wheel at 1e7 samples) and its fit now starts on a subsample; fitting/wheel_model_test holds
// that fit to the full-data reference path instead.
//
// Tolerance: |new - reference| <= 1e-9 |reference| + 1e-12 in the key's own unit. The relative
// part allows a different order of floating-point sums (another compiler, the sanitizer build);
// the absolute part, 1e-12 mm or um, allows values that are zero up to round-off.

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "core/testing/testing.h"

namespace arcwheel {
namespace {

using testing::RunArcwheel;
using testing::SourceDir;
using testing::TempDir;

constexpr double kRelative = 1e-9;
constexpr double kAbsolute = 1e-12;

nlohmann::json ReadJson(const std::filesystem::path& path) {
  std::ifstream in(path);
  return nlohmann::json::parse(in);
}

// Every leaf of `reference` must be in `actual`, numbers within the tolerance, the rest equal.
void ExpectSameNumbers(const nlohmann::json& reference, const nlohmann::json& actual,
                       const std::string& where, int& compared) {
  if (reference.is_object()) {
    for (const auto& [key, value] : reference.items()) {
      if (where.empty() && key == "model") continue;
      ASSERT_TRUE(actual.contains(key)) << where << "/" << key << " is missing";
      ExpectSameNumbers(value, actual[key], where + "/" + key, compared);
    }
  } else if (reference.is_array()) {
    ASSERT_TRUE(actual.is_array()) << where;
    ASSERT_EQ(actual.size(), reference.size()) << where;
    for (std::size_t i = 0; i < reference.size(); ++i) {
      ExpectSameNumbers(reference[i], actual[i], where + "/" + std::to_string(i), compared);
    }
  } else if (reference.is_number_float() || (reference.is_number() && actual.is_number_float())) {
    ASSERT_TRUE(actual.is_number()) << where;
    const double expected = reference.get<double>();
    const double value = actual.get<double>();
    EXPECT_LE(std::abs(value - expected), kRelative * std::abs(expected) + kAbsolute)
        << where << ": " << value << " against " << expected;
    ++compared;
  } else {
    EXPECT_EQ(actual, reference) << where;
    ++compared;
  }
}

void ExpectSameSummary(const std::string& scan, const std::string& reference_name) {
  TempDir dir;
  const auto run = RunArcwheel("process -q " + scan + " -o " + (dir / "out").string());
  ASSERT_EQ(run.exit_status, 0) << run.output;
  nlohmann::json reference = ReadJson(SourceDir() / "testdata" / "regression" / reference_name);
  int compared = 0;
  ExpectSameNumbers(reference, ReadJson(dir / "out" / "summary.json"), "", compared);
  EXPECT_GT(compared, 3000) << "the reference holds every per-phase number";
}

// Simulates a scan with `options` and checks that its summary matches `reference_name`.
void ExpectSameSummaryOfSimulation(const std::string& options, const std::string& reference_name) {
  TempDir dir;
  const std::string scan = (dir / "scan.h5").string();
  const auto simulated = RunArcwheel("simulate " + scan + " " + options);
  ASSERT_EQ(simulated.exit_status, 0) << simulated.output;
  ExpectSameSummary(scan, reference_name);
}

TEST(SameResults, ShippedScan) {
  ExpectSameSummary((SourceDir() / "testdata" / "paper_wheel_scan.h5").string(),
                    "paper_wheel_scan.summary.json");
}

// float32 HDF5, nominal speed, isolated spikes: the benchmark's scan (benchmarks/process_bench.sh).
TEST(SameResults, SimulatedN1e6Float32WithSpikes) {
  ExpectSameSummaryOfSimulation(
      "--sample-period-s 1e-5 --feed-mm-per-min 132 --noise-um 0.3 --radial-harmonic 1:3:40 "
      "--radial-harmonic 3:0.8:15 --spike-rate 1e-5",
      "sim_1e6_spikes.summary.json");
}

// float64 with time and encoder columns, dropouts and bursts, radius lobing and a profile error.
TEST(SameResults, SimulatedN1e6Float64EncoderDropoutsBursts) {
  ExpectSameSummaryOfSimulation(
      "--sample-period-s 1e-5 --feed-mm-per-min 132 --noise-um 0.5 --encoder --time-column --float64 "
      "--dropout-rate 1e-5 --burst-rate 1e-5 --radius-harmonic 3:0.002:10 --profile-legendre-um 0 0 0 0.5 "
      "--seed 7",
      "sim_1e6_encoder_dropouts_bursts.summary.json");
}

TEST(SameResults, SimulatedN1e7Float32WithSpikes) {
  ExpectSameSummaryOfSimulation(
      "--sample-period-s 1e-5 --feed-mm-per-min 13.2 --noise-um 0.3 --radial-harmonic 1:3:40 "
      "--radial-harmonic 3:0.8:15 --spike-rate 1e-5",
      "sim_1e7_spikes.summary.json");
}

}  // namespace
}  // namespace arcwheel
