#include "characteristics/roundness.h"

#include <fmt/core.h>

#include <algorithm>
#include <cmath>
#include <numbers>

#include "characteristics/gaussian_filter.h"
#include "core/check.h"
#include "core/error.h"

namespace arcwheel::characteristics {
namespace {

constexpr std::string_view kRoundnessStage = "characteristics.roundness";
constexpr double kMmToUm = 1000.0;
// Relative departure of a step from 360 / n that is still "equally spaced": a hundredth of a step
// moves a sample of an eccentric profile by 1e-4 rad times the eccentricity.
constexpr double kStepTolerance = 0.01;

// a - b folded into (-180, 180].
double AngleDifferenceDeg(double a, double b) {
  double difference = std::fmod(a - b, 360.0);
  if (difference > 180.0) difference -= 360.0;
  if (difference <= -180.0) difference += 360.0;
  return difference;
}

}  // namespace

std::vector<std::string> RoundnessOptions::Problems() const {
  std::vector<std::string> problems;
  if (filter_cutoff_upr && !(*filter_cutoff_upr > 0 && std::isfinite(*filter_cutoff_upr))) {
    problems.push_back(fmt::format("filter_cutoff_upr = {} violates > 0", *filter_cutoff_upr));
  }
  if (max_harmonic_upr < 1)
    problems.push_back(fmt::format("max_harmonic_upr = {} violates >= 1", max_harmonic_upr));
  const std::vector<std::string> association_problems =
      AssociationOptions{.association = association}.Problems();
  problems.insert(problems.end(), association_problems.begin(), association_problems.end());
  return problems;
}

std::string RoundnessOperator::Describe(std::string_view parameter) const {
  const std::string filter = filter_cutoff_upr ? fmt::format("{:g} UPR", *filter_cutoff_upr) : "no filter";
  return fmt::format("{}, {}, {}", parameter, filter, AssociationAbbreviation(association));
}

AngleSpacing CheckAngleSpacing(std::span<const double> angle_deg) {
  AngleSpacing spacing;
  const std::size_t n = angle_deg.size();
  if (n < 2) return spacing;
  std::vector<double> steps(n);
  for (std::size_t i = 0; i < n; ++i) {
    steps[i] = AngleDifferenceDeg(angle_deg[(i + 1) % n], angle_deg[i]);
    spacing.turn_deg += steps[i];
  }
  spacing.expected_step_deg = (spacing.turn_deg < 0 ? -360.0 : 360.0) / static_cast<double>(n);
  double largest_departure = -1.0;
  for (std::size_t i = 0; i < n; ++i) {
    const double departure = std::abs(steps[i] - spacing.expected_step_deg);
    if (departure > largest_departure) {
      largest_departure = departure;
      spacing.largest_gap_index = static_cast<int>(i);
      spacing.largest_gap_deg = steps[i];
    }
  }
  spacing.equally_spaced = std::abs(std::abs(spacing.turn_deg) - 360.0) < 1e-6 &&
                           largest_departure <= kStepTolerance * std::abs(spacing.expected_step_deg);
  return spacing;
}

RoundnessParameters ParametersAbout(const AssociatedCircle& reference, std::span<const double> x_mm,
                                    std::span<const double> y_mm) {
  double highest = -std::numeric_limits<double>::infinity();
  double lowest = std::numeric_limits<double>::infinity();
  double sum_squares = 0.0;
  for (std::size_t i = 0; i < x_mm.size(); ++i) {
    const double deviation =
        std::hypot(x_mm[i] - reference.center_x_mm, y_mm[i] - reference.center_y_mm) - reference.radius_mm;
    highest = std::max(highest, deviation);
    lowest = std::min(lowest, deviation);
    sum_squares += deviation * deviation;
  }
  RoundnessParameters out;
  // Rounding may put a support point a few 1e-13 mm on the wrong side of its own circle.
  out.ronp_um = std::max(highest, 0.0) * kMmToUm;
  out.ronv_um = std::max(-lowest, 0.0) * kMmToUm;
  out.ront_um = (highest - lowest) * kMmToUm;
  out.ronq_um = std::sqrt(sum_squares / static_cast<double>(x_mm.size())) * kMmToUm;
  return out;
}

RoundnessResult EvaluateRoundness(std::span<const double> angle_deg, std::span<const double> radius_mm,
                                  const RoundnessOptions& options) {
  ThrowIfProblems(ErrorCode::kInvalidOption, kRoundnessStage, options.Problems());
  ARCWHEEL_CHECK(angle_deg.size() == radius_mm.size())
      << angle_deg.size() << " angles, " << radius_mm.size() << " radii";
  const std::size_t n = radius_mm.size();
  if (n < 8)
    throw Error(ErrorCode::kBadInput, kRoundnessStage,
                fmt::format("a closed profile needs at least 8 points, got {}", n));
  for (std::size_t i = 0; i < n; ++i) {
    if (!(radius_mm[i] > 0) || !std::isfinite(radius_mm[i]) || !std::isfinite(angle_deg[i])) {
      throw Error(ErrorCode::kBadInput, kRoundnessStage,
                  fmt::format("point {}: radius {} mm at {} deg", i, radius_mm[i], angle_deg[i]));
    }
  }
  const AngleSpacing spacing = CheckAngleSpacing(angle_deg);
  if (!spacing.equally_spaced) {
    throw Error(
        ErrorCode::kBadInput, kRoundnessStage,
        fmt::format("the angles are not equally spaced over one turn: the largest gap, {} deg from point {} "
                    "to the next, is not {} deg (360 / {} points); they turn {} deg",
                    spacing.largest_gap_deg, spacing.largest_gap_index, spacing.expected_step_deg, n,
                    spacing.turn_deg));
  }
  if (options.filter_cutoff_upr && *options.filter_cutoff_upr > 0.5 * static_cast<double>(n)) {
    throw Error(ErrorCode::kInvalidOption, kRoundnessStage,
                fmt::format("cut-off {} UPR is above half the {} points of the profile ({} UPR)",
                            *options.filter_cutoff_upr, n, 0.5 * static_cast<double>(n)));
  }
  const std::vector<double> filtered = options.filter_cutoff_upr
                                           ? FilterClosedProfile(radius_mm, *options.filter_cutoff_upr)
                                           : std::vector<double>(radius_mm.begin(), radius_mm.end());
  std::vector<double> x(n), y(n);
  for (std::size_t i = 0; i < n; ++i) {
    const double angle_rad = angle_deg[i] * std::numbers::pi / 180.0;
    x[i] = filtered[i] * std::cos(angle_rad);
    y[i] = filtered[i] * std::sin(angle_rad);
  }
  RoundnessResult result;
  result.op = {.filter_cutoff_upr = options.filter_cutoff_upr, .association = options.association};
  result.reference = AssociateCircle(x, y, {.association = options.association});
  if (!result.reference.IsCertified()) {
    throw Error(ErrorCode::kFitFailed, kRoundnessStage,
                fmt::format("no {} reference circle: {}", AssociationName(options.association),
                            result.reference.message));
  }
  const RoundnessParameters parameters = ParametersAbout(result.reference, x, y);
  result.ront_um = parameters.ront_um;
  result.ronp_um = parameters.ronp_um;
  result.ronv_um = parameters.ronv_um;
  result.ronq_um = parameters.ronq_um;
  result.filtered_radius_mm = filtered;
  const int max_harmonic = std::min(static_cast<int>(n / 2) - 1, options.max_harmonic_upr);
  result.harmonic_amplitude_um = HarmonicAmplitudes(radius_mm, max_harmonic);
  for (double& amplitude : result.harmonic_amplitude_um) amplitude *= kMmToUm;
  return result;
}

}  // namespace arcwheel::characteristics
