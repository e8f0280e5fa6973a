#include "processing/process_scan.h"

#include <fmt/core.h>

#include <algorithm>
#include <cmath>
#include <optional>
#include <span>
#include <string>
#include <type_traits>
#include <vector>

#include "core/error.h"
#include "core/free_memory.h"
#include "core/interrupt.h"
#include "processing/noise.h"
#include "processing/stuck_readings.h"

namespace arcwheel::processing {
namespace {

constexpr const char* kProcessScanStage = "processing";

// rho = radius_sign * z, in place (exact in float and double); invalid samples stay NaN.
template <typename T>
void ToRadialCoordinate(const acquisition::Scan& scan, std::span<T> rho) {
  if (scan.metadata.radius_sign < 0) {
    for (T& v : rho) v = -v;
  }
}

// method.md A.7: a beam at lateral offset e reads h = sqrt(R^2 - e^2) of a rim at radius R.
// With the sensor's zero at radius R0 (rho = h - R0): R = sqrt((R0 + rho)^2 + e^2).
void CorrectBeamOffset(std::span<double> rho, double offset_mm, double apex_radius_mm) {
  std::vector<double> finite;
  for (std::size_t i = 0; i < rho.size(); i += std::max<std::size_t>(1, rho.size() / 100000)) {
    if (std::isfinite(rho[i])) finite.push_back(rho[i]);
  }
  // The apex of the rim is where rho peaks; its radius is the wheel's.
  const auto top = finite.begin() + static_cast<long>(0.995 * static_cast<double>(finite.size()));
  std::nth_element(finite.begin(), top, finite.end());
  const double zero_radius_mm = apex_radius_mm - *top;
  const double e2 = offset_mm * offset_mm;
  for (double& v : rho) {
    if (std::isfinite(v)) v = std::sqrt((zero_radius_mm + v) * (zero_radius_mm + v) + e2) - zero_radius_mm;
  }
}

// Samples a turn over the whole scan, from its own timing (the nominal speed, or the encoder);
// nothing when the scan gives no way to tell a turn (it is refused further on). One geometry, which
// with an encoder unwraps the whole angle column, serves every use.
std::optional<double> SamplesPerTurn(const acquisition::Scan& scan) {
  if (scan.size() < 2 || (!scan.has_encoder() && !scan.metadata.spindle_rpm)) return std::nullopt;
  const HelixGeometry geometry(scan, scan.metadata.spindle_rpm.value_or(0.0));
  const double turns = (geometry.PhaseAt(scan.size() - 1) - geometry.PhaseAt(0)) / 360.0;
  if (!(turns > 0.0)) return std::nullopt;
  return static_cast<double>(scan.size()) / turns;
}

// Samples in `stuck_run_deg` of a turn (at least 16); 0 when the run is disabled or the scan
// gives no way to tell a turn.
std::size_t StuckRunSamples(std::optional<double> samples_per_turn, double stuck_run_deg) {
  if (stuck_run_deg <= 0.0 || !samples_per_turn) return 0;
  return std::max<std::size_t>(
      16, static_cast<std::size_t>(std::ceil(*samples_per_turn * stuck_run_deg / 360.0)));
}

void CheckOptions(const acquisition::Scan& scan, const ProcessOptions& options) {
  ThrowIfProblems(ErrorCode::kInvalidOption, kProcessScanStage, options.Problems());
  if (options.rpm_source == RpmSource::kEncoder && !scan.has_encoder()) {
    throw Error(ErrorCode::kInvalidOption, kProcessScanStage,
                "'" + scan.path + "' has no angle column for --rpm-source encoder");
  }
}

// A helix sampled fewer times a turn than this tells nothing of the wheel's phase: the map's
// sections, the spline's knots and the speed estimate's phase bins all need several samples a
// turn. Real scans take hundreds (a 50 kHz sensor on a wheel at 6000 rpm: 500).
constexpr double kMinSamplesPerTurn = 16.0;

// Refuses a scan whose settings give fewer than kMinSamplesPerTurn samples a turn (a spindle speed
// in the wrong unit, say): left to the steps, its turns would outnumber its samples.
void CheckSamplesPerTurn(const acquisition::Scan& scan, std::optional<double> samples_per_turn) {
  if (!samples_per_turn || *samples_per_turn >= kMinSamplesPerTurn) return;
  const std::string settings = scan.has_encoder()
                                   ? std::string("by its angle column")
                                   : fmt::format("at spindle_rpm {:g}", *scan.metadata.spindle_rpm);
  throw Error(ErrorCode::kBadInput, kProcessScanStage,
              fmt::format("'{}': {:.3g} samples a turn {} over {:.4g} turns; a helical scan needs at least "
                          "{:g} a turn to resolve the wheel's phase (is spindle_rpm in rev/min and "
                          "sample_period_s in seconds?)",
                          scan.path, *samples_per_turn, settings,
                          static_cast<double>(scan.size()) / *samples_per_turn, kMinSamplesPerTurn));
}

// Step 1: the span from the first to the last valid sample (DropStuckSensorRuns counts them).
template <typename T>
void FindValidSpan(std::span<const T> rho, ProcessedScan& out) {
  const auto finite = [](T v) { return std::isfinite(static_cast<double>(v)); };
  const auto first = std::find_if(rho.begin(), rho.end(), finite);
  const auto last = std::find_if(rho.rbegin(), rho.rend(), finite);
  out.first_valid = static_cast<std::size_t>(first - rho.begin());
  out.last_valid = rho.size() - 1 - static_cast<std::size_t>(last - rho.rbegin());
}

// Drops runs of equal readings (a stuck sensor); refuses a scan that is nothing else.
template <typename T>
void DropStuckSensorRuns(const acquisition::Scan& scan, std::span<T> rho, std::size_t min_run,
                         ProcessedScan& out) {
  out.stuck = DropStuckReadings(rho, min_run);
  out.valid_samples = out.stuck.valid;
  if (out.stuck.dropped > 0 && out.stuck.dropped == out.valid_samples) {
    throw Error(
        ErrorCode::kBadInput, kProcessScanStage,
        fmt::format("'{}': every reading lies in a run of equal values (longest {} samples): the sensor is "
                    "stuck or saturated",
                    scan.path, out.stuck.longest_run));
  }
  if (out.stuck.dropped > 0) {
    out.warnings.push_back(
        fmt::format("dropped {} samples in {} run(s) of equal readings (longest {} samples; a run of "
                    "{} or more is a stuck or saturated sensor): check the sensor",
                    out.stuck.dropped, out.stuck.runs, out.stuck.longest_run, out.stuck.min_run));
  }
}

// Steps 2-3: noise, despiking, and the noise again of what is left.
template <typename T>
void DespikeAndEstimateNoise(std::span<T> rho, const DespikeOptions& options, ProcessedScan& out) {
  out.noise_sigma_mm = EstimateNoiseSigmaMm(std::span<const T>(rho));
  out.despike = Despike(std::span<T>(rho), out.noise_sigma_mm, options);
  // The noise that matters for the sigmas is that of the samples the map is built from.
  out.noise_sigma_mm = EstimateNoiseSigmaMm(std::span<const T>(rho));
  if (out.despike.rejected > out.valid_samples / 10) {
    out.warnings.push_back(
        fmt::format("despiking rejected {} of {} valid samples: check the threshold ({:.3g} um)",
                    out.despike.rejected, out.valid_samples, out.despike.threshold_um));
  }
}

// Step 4, when a beam offset is given.
void CorrectBeamOffsetIfAsked(const acquisition::Scan& scan, std::span<double> rho,
                              const ProcessOptions& options) {
  if (options.beam_offset_mm == 0.0) return;
  double radius = options.wheel_radius_mm;
  if (radius <= 0 && scan.metadata.wheel_diameter_mm) radius = *scan.metadata.wheel_diameter_mm / 2.0;
  if (radius <= 0) {
    throw Error(ErrorCode::kInvalidOption, kProcessScanStage,
                "the beam-offset correction needs the wheel radius: give --wheel-radius-mm or a "
                "wheel_diameter_mm attribute");
  }
  CorrectBeamOffset(rho, options.beam_offset_mm, radius);
}

// Step 5 without an encoder: the nominal speed, or the estimate when it is significant or asked for.
template <typename T>
void ChooseSpeedWithoutEncoder(const acquisition::Scan& scan, std::span<const T> rho,
                               const ProcessOptions& options, ProcessedScan& out) {
  if (!scan.metadata.spindle_rpm) {
    throw Error(ErrorCode::kBadInput, kProcessScanStage, "'" + scan.path + "' lacks spindle_rpm");
  }
  out.rpm_used = *scan.metadata.spindle_rpm;
  out.phase_source = PhaseSource::kNominal;
  if (options.rpm_source == RpmSource::kNominal || scan.has_encoder()) return;
  out.speed = EstimateSpindleSpeed(scan, rho, options.speed);
  const bool forced = options.rpm_source == RpmSource::kEstimate;
  if (out.speed.available && (out.speed.significant || forced)) {
    out.rpm_used = out.speed.fitted_rpm;
    out.phase_source = PhaseSource::kEstimated;
    out.warnings.push_back(
        fmt::format("spindle speed estimated from the data: {:.6f} rpm (nominal {:.6f}, sigma {:.2g})",
                    out.speed.fitted_rpm, out.speed.nominal_rpm, out.speed.sigma_rpm));
  }
  if (!out.speed.note.empty()) out.warnings.push_back(out.speed.note);
}

// Step 5: the encoder when there is one and it is allowed, else ChooseSpeedWithoutEncoder.
template <typename T>
void ChooseSpeed(const acquisition::Scan& scan, std::span<const T> rho, const ProcessOptions& options,
                 ProcessedScan& out) {
  const bool use_encoder = scan.has_encoder() && (options.rpm_source == RpmSource::kAuto ||
                                                  options.rpm_source == RpmSource::kEncoder);
  if (use_encoder) {
    out.phase_source = PhaseSource::kEncoder;
    out.rpm_used = HelixGeometry(scan, 0.0).rpm();
  } else {
    ChooseSpeedWithoutEncoder(scan, rho, options, out);
  }
}

}  // namespace

std::vector<std::string> ProcessOptions::Problems() const {
  std::vector<std::string> problems = despike.Problems();
  for (std::string& p : speed.Problems()) problems.push_back(std::move(p));
  for (std::string& p : map.Problems()) problems.push_back(std::move(p));
  if (!std::isfinite(beam_offset_mm))
    problems.push_back(fmt::format("--beam-offset-mm = {} violates finite", beam_offset_mm));
  if (!std::isfinite(wheel_radius_mm))
    problems.push_back(fmt::format("--wheel-radius-mm = {} violates finite", wheel_radius_mm));
  if (!(stuck_run_deg >= 0.0 && stuck_run_deg <= 360.0))
    problems.push_back(fmt::format("--stuck-run-deg = {} violates 0..360", stuck_run_deg));
  return problems;
}

namespace {

// Whose estimate fills the map's values: the helix spline's sections (ProcessScan), or none yet,
// the sample fit's to come (ProcessScanInPlace).
enum class MapValues { kFromHelixSpline, kLeftToTheSampleFit };

// The steps on the readings, in float or double as the scan holds them.
template <typename T>
ProcessedScan ProcessReadings(acquisition::Scan& scan, std::span<T> rho, const ProcessOptions& options,
                              std::optional<double> samples_per_turn, MapValues values) {
  ProcessedScan out;
  StageClock& clock = out.timings;
  out.samples = scan.size();
  out.warnings = scan.metadata.notes;  // what the reader noticed comes first
  clock.Start("valid span");
  ToRadialCoordinate(scan, rho);
  FindValidSpan(std::span<const T>(rho), out);
  ThrowIfInterrupted();

  clock.Start("stuck readings");
  DropStuckSensorRuns(scan, rho, StuckRunSamples(samples_per_turn, options.stuck_run_deg), out);
  clock.Start("noise and despike");
  DespikeAndEstimateNoise(rho, options.despike, out);
  ThrowIfInterrupted();

  clock.Start("spindle speed");
  if constexpr (std::is_same_v<T, double>) CorrectBeamOffsetIfAsked(scan, rho, options);
  ChooseSpeed(scan, std::span<const T>(rho), options, out);
  ThrowIfInterrupted();

  ReturnFreedMemory();  // the speed estimate's and the despiker's arrays
  const HelixGeometry geometry(scan, out.rpm_used);
  out.map = values == MapValues::kFromHelixSpline
                ? BuildWheelMap(std::span<const T>(rho), geometry, out.noise_sigma_mm, out.despike.indices,
                                options.map, &clock)
                : PlanWheelMap(std::span<const T>(rho), geometry, out.noise_sigma_mm, out.despike.indices,
                               options.map, &clock);
  return out;
}

// Steps 1-5 on the scan's readings in place, then the map as `values` says.
ProcessedScan ProcessInPlace(acquisition::Scan& scan, const ProcessOptions& options, MapValues values) {
  CheckOptions(scan, options);
  const std::optional<double> samples_per_turn = SamplesPerTurn(scan);
  CheckSamplesPerTurn(scan, samples_per_turn);
  // Steps that change readings by arithmetic work in double, so that their results do not depend
  // on how the file stored the readings.
  if (options.beam_offset_mm != 0.0 || options.despike.method == DespikeMethod::kMovingMean) {
    scan.WidenToDouble();
  }
  return acquisition::VisitReadings(scan, [&](auto& rho) {
    return ProcessReadings(scan, std::span(rho), options, samples_per_turn, values);
  });
}

}  // namespace

ProcessedScan ProcessScan(acquisition::Scan scan, const ProcessOptions& options) {
  return ProcessInPlace(scan, options, MapValues::kFromHelixSpline);
}

ProcessedScan ProcessScanInPlace(acquisition::Scan& scan, const ProcessOptions& options) {
  return ProcessInPlace(scan, options, MapValues::kLeftToTheSampleFit);
}

}  // namespace arcwheel::processing
