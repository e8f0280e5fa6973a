#include "frames/force_centre.h"

#include <fmt/core.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>

#include "core/error.h"
#include "core/statistics.h"

namespace arcwheel::frames {
namespace {

constexpr const char* kRecordStage = "frames.force_record";
constexpr const char* kForceCentreStage = "frames.headcenter";

struct RecordChannel {
  const char* name;
  std::vector<double> ForceRecord::*values;
};
constexpr std::array<RecordChannel, 7> kRecordChannels = {{
    {"t_s", &ForceRecord::t_s},
    {"Fx_N", &ForceRecord::fx_N},
    {"Fy_N", &ForceRecord::fy_N},
    {"Fz_N", &ForceRecord::fz_N},
    {"Mx_Nmm", &ForceRecord::mx_Nmm},
    {"My_Nmm", &ForceRecord::my_Nmm},
    {"Mz_Nmm", &ForceRecord::mz_Nmm},
}};

}  // namespace

void ValidateForceRecord(const ForceRecord& record) {
  const size_t n = record.t_s.size();
  if (n == 0)
    throw Error(ErrorCode::kBadInput, kRecordStage, fmt::format("'{}' has no samples", record.source));
  for (const RecordChannel& channel : kRecordChannels) {
    const std::vector<double>& values = record.*channel.values;
    if (values.size() != n) {
      throw Error(ErrorCode::kBadInput, kRecordStage,
                  fmt::format("'{}': channel {} has {} samples but t_s has {}", record.source, channel.name,
                              values.size(), n));
    }
    for (size_t i = 0; i < n; ++i) {
      if (!std::isfinite(values[i])) {
        throw Error(
            ErrorCode::kBadInput, kRecordStage,
            fmt::format("'{}': channel {} sample {} is {}", record.source, channel.name, i + 1, values[i]));
      }
    }
  }
  for (size_t i = 1; i < n; ++i) {
    if (!(record.t_s[i] > record.t_s[i - 1])) {
      throw Error(ErrorCode::kBadInput, kRecordStage,
                  fmt::format("'{}': t_s is not increasing at sample {} ({} after {})", record.source, i + 1,
                              record.t_s[i], record.t_s[i - 1]));
    }
  }
}

Wrench MeanWrench(const ForceRecord& unloaded) {
  ValidateForceRecord(unloaded);
  const auto mean = [](const std::vector<double>& v) {
    double sum = 0.0;
    for (double x : v) sum += x;
    return sum / static_cast<double>(v.size());
  };
  Wrench tare;
  tare.force_N = {mean(unloaded.fx_N), mean(unloaded.fy_N), mean(unloaded.fz_N)};
  tare.moment_Nmm = {mean(unloaded.mx_Nmm), mean(unloaded.my_Nmm), mean(unloaded.mz_Nmm)};
  return tare;
}

ForceRecord Tare(const ForceRecord& record, const Wrench& tare) {
  ForceRecord tared = record;
  const std::array<std::pair<std::vector<double>*, double>, 6> offsets = {{
      {&tared.fx_N, tare.force_N.x()},
      {&tared.fy_N, tare.force_N.y()},
      {&tared.fz_N, tare.force_N.z()},
      {&tared.mx_Nmm, tare.moment_Nmm.x()},
      {&tared.my_Nmm, tare.moment_Nmm.y()},
      {&tared.mz_Nmm, tare.moment_Nmm.z()},
  }};
  for (const auto& [values, offset] : offsets) {
    for (double& v : *values) v -= offset;
  }
  return tared;
}

std::vector<std::string> ContactSolveOptions::Problems() const {
  std::vector<std::string> problems;
  if (!std::isfinite(platform_height_mm))
    problems.push_back(fmt::format("--z0-mm = {} violates finite", platform_height_mm));
  if (!(min_normal_force_fraction >= 0.0 && min_normal_force_fraction < 1.0)) {
    problems.push_back(fmt::format("--min-force-fraction = {} violates [0, 1)", min_normal_force_fraction));
  }
  if (!(min_normal_force_N >= 0.0))
    problems.push_back(fmt::format("--min-force-N = {} violates >= 0", min_normal_force_N));
  return problems;
}

ContactCentre SolveContactCentre(const ForceRecord& tared, const ContactSolveOptions& options) {
  ThrowIfProblems(ErrorCode::kInvalidOption, kForceCentreStage, options.Problems());
  ValidateForceRecord(tared);
  const size_t n = tared.size();
  const double z0 = options.platform_height_mm;
  std::vector<double> normal(n);
  for (size_t i = 0; i < n; ++i) normal[i] = std::abs(tared.fz_N[i]);
  ContactCentre result;
  result.samples_total = static_cast<int>(n);
  result.normal_force_threshold_N =
      std::max(options.min_normal_force_N, options.min_normal_force_fraction * Median(normal));

  std::vector<size_t> used;
  for (size_t i = 0; i < n; ++i) {
    if (normal[i] >= result.normal_force_threshold_N && normal[i] > 0.0) used.push_back(i);
  }
  if (used.size() < 3) {
    throw Error(ErrorCode::kFitFailed, kForceCentreStage,
                fmt::format("'{}': only {} of {} samples carry a normal force of at least {:.4g} N",
                            tared.source, used.size(), n, result.normal_force_threshold_N));
  }
  // Normal equations of the two decoupled one-parameter regressions (see the header).
  double sum_fz2 = 0.0, sum_x = 0.0, sum_y = 0.0, sum_fz = 0.0;
  for (size_t i : used) {
    const double fz = tared.fz_N[i];
    sum_fz2 += fz * fz;
    sum_fz += fz;
    sum_x += fz * (z0 * tared.fx_N[i] - tared.my_Nmm[i]);
    sum_y += fz * (tared.mx_Nmm[i] + z0 * tared.fy_N[i]);
  }
  const double x0 = sum_x / sum_fz2;
  const double y0 = sum_y / sum_fz2;
  double rss_x = 0.0, rss_y = 0.0, couple = 0.0;
  for (size_t i : used) {
    const double fz = tared.fz_N[i];
    const double rx = tared.mx_Nmm[i] + z0 * tared.fy_N[i] - y0 * fz;  // Mx equation
    const double ry = tared.my_Nmm[i] - z0 * tared.fx_N[i] + x0 * fz;  // My equation
    rss_x += rx * rx;
    rss_y += ry * ry;
    couple += tared.mz_Nmm[i] - (x0 * tared.fy_N[i] - y0 * tared.fx_N[i]);
  }
  const auto m = static_cast<double>(used.size());
  result.centre_mm = {x0, y0};
  // x0 comes from the My equation, y0 from the Mx equation; each has one parameter.
  result.covariance_mm2(0, 0) = rss_y / (m - 1.0) / sum_fz2;
  result.covariance_mm2(1, 1) = rss_x / (m - 1.0) / sum_fz2;
  result.samples_used = static_cast<int>(used.size());
  result.mean_normal_force_N = sum_fz / m;
  result.rms_moment_residual_Nmm = {std::sqrt(rss_x / m), std::sqrt(rss_y / m)};
  result.friction_couple_Nmm = couple / m;
  return result;
}

MoveTables TabulateMoves(std::span<const MoveSample> samples) {
  if (samples.empty()) throw Error(ErrorCode::kBadInput, kForceCentreStage, "no records to tabulate");
  constexpr double kSamePositionMm = 1e-6;
  MoveTables tables;
  std::vector<std::vector<Eigen::Vector2d>> groups;
  for (const MoveSample& sample : samples) {
    auto row = std::find_if(tables.repeatability.begin(), tables.repeatability.end(),
                            [&](const RepeatabilityRow& r) {
                              return (r.commanded_mm - sample.commanded_mm).norm() <= kSamePositionMm;
                            });
    if (row == tables.repeatability.end()) {
      tables.repeatability.push_back({.commanded_mm = sample.commanded_mm});
      groups.emplace_back();
      row = tables.repeatability.end() - 1;
    }
    groups[static_cast<size_t>(row - tables.repeatability.begin())].push_back(sample.solved_mm);
  }
  for (size_t g = 0; g < groups.size(); ++g) {
    RepeatabilityRow& row = tables.repeatability[g];
    row.count = static_cast<int>(groups[g].size());
    for (const auto& p : groups[g]) row.mean_mm += p / row.count;
    Eigen::Vector2d sum_squares = Eigen::Vector2d::Zero();
    for (const auto& p : groups[g]) {
      sum_squares += (p - row.mean_mm).cwiseAbs2();
      row.max_deviation_mm = std::max(row.max_deviation_mm, (p - row.mean_mm).norm());
    }
    if (row.count > 1) row.std_mm = (sum_squares / (row.count - 1)).cwiseSqrt();
    tables.worst_repeatability_mm = std::max(tables.worst_repeatability_mm, row.max_deviation_mm);
  }
  const RepeatabilityRow& reference = tables.repeatability.front();
  tables.reference_mm = reference.commanded_mm;
  for (size_t g = 1; g < groups.size(); ++g) {
    const RepeatabilityRow& row = tables.repeatability[g];
    AccuracyRow accuracy{.commanded_mm = row.commanded_mm};
    accuracy.commanded_move_mm = (row.commanded_mm - reference.commanded_mm).norm();
    accuracy.solved_move_mm = (row.mean_mm - reference.mean_mm).norm();
    accuracy.error_mm = accuracy.solved_move_mm - accuracy.commanded_move_mm;
    tables.worst_accuracy_mm = std::max(tables.worst_accuracy_mm, std::abs(accuracy.error_mm));
    tables.accuracy.push_back(accuracy);
  }
  return tables;
}

namespace {

ForceRecord SimulateRecord(const ForceSimulation& s, bool loaded, std::mt19937& rng) {
  ThrowIfProblems(ErrorCode::kInvalidOption, kForceCentreStage, s.Problems());
  const auto n = static_cast<size_t>(std::llround(s.duration_s * s.sample_rate_hz));
  const double omega = 2.0 * std::numbers::pi * s.pad_rpm / 60.0;
  const Eigen::Vector3d p(s.centre_mm.x(), s.centre_mm.y(), s.platform_height_mm);
  const double force_sigma = s.noise_fraction * s.normal_force_N;
  const double moment_sigma = force_sigma * p.norm();
  std::normal_distribution<double> force_noise(0.0, force_sigma);
  std::normal_distribution<double> moment_noise(0.0, moment_sigma);
  ForceRecord record;
  record.source = loaded ? "simulated loaded record" : "simulated unloaded record";
  for (size_t i = 0; i < n; ++i) {
    const double t = static_cast<double>(i) / s.sample_rate_hz;
    Eigen::Vector3d force = Eigen::Vector3d::Zero();
    Eigen::Vector3d moment = Eigen::Vector3d::Zero();
    if (loaded) {
      const double ramp = std::min(1.0, t / std::max(1e-12, s.approach_fraction * s.duration_s));
      const double normal = s.normal_force_N * ramp * (1.0 + s.force_ripple * std::sin(omega * t));
      // The pad's net friction: a drag along x plus a component turning with the pad.
      const double friction = s.friction_coefficient * normal;
      force = {friction * (0.5 + 0.5 * std::cos(omega * t)), 0.5 * friction * std::sin(omega * t), -normal};
      moment = p.cross(force);
      moment.z() += s.friction_couple_Nmm * normal / 30.0;
    }
    force += s.tare.force_N;
    moment += s.tare.moment_Nmm;
    record.t_s.push_back(t);
    record.fx_N.push_back(force.x() + force_noise(rng));
    record.fy_N.push_back(force.y() + force_noise(rng));
    record.fz_N.push_back(force.z() + force_noise(rng));
    record.mx_Nmm.push_back(moment.x() + moment_noise(rng));
    record.my_Nmm.push_back(moment.y() + moment_noise(rng));
    record.mz_Nmm.push_back(moment.z() + moment_noise(rng));
  }
  return record;
}

}  // namespace

std::vector<std::string> ForceSimulation::Problems() const {
  std::vector<std::string> problems;
  if (!centre_mm.allFinite()) {
    problems.push_back(fmt::format("--centre-mm = {},{} violates finite", centre_mm.x(), centre_mm.y()));
  }
  if (!std::isfinite(platform_height_mm))
    problems.push_back(fmt::format("--z0-mm = {} violates finite", platform_height_mm));
  const bool duration_ok = duration_s > 0.0 && std::isfinite(duration_s);
  const bool rate_ok = sample_rate_hz > 0.0 && std::isfinite(sample_rate_hz);
  if (!duration_ok) problems.push_back(fmt::format("--duration-s = {} violates finite and > 0", duration_s));
  if (!rate_ok) problems.push_back(fmt::format("--rate-hz = {} violates finite and > 0", sample_rate_hz));
  // Only with both valid does their product say anything of its own.
  const double samples = duration_s * sample_rate_hz;
  if (duration_ok && rate_ok && !(samples >= 1.0 && samples <= 1e8)) {
    problems.push_back(fmt::format("--duration-s * --rate-hz = {} samples violates 1 .. 1e8", samples));
  }
  if (!(normal_force_N >= 0.0 && std::isfinite(normal_force_N)))
    problems.push_back(fmt::format("--normal-force-N = {} violates finite and >= 0", normal_force_N));
  if (!(noise_fraction >= 0.0 && std::isfinite(noise_fraction)))
    problems.push_back(fmt::format("--noise = {} violates finite and >= 0", noise_fraction));
  return problems;
}

ForceRecord SimulateForceRecord(const ForceSimulation& simulation, std::mt19937& rng) {
  return SimulateRecord(simulation, true, rng);
}

ForceRecord SimulateUnloadedRecord(const ForceSimulation& simulation, std::mt19937& rng) {
  return SimulateRecord(simulation, false, rng);
}

}  // namespace arcwheel::frames
