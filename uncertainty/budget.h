#pragma once
// An uncertainty budget after the GUM (JCGM 100:2008, "Evaluation of measurement data - Guide to
// the expression of uncertainty in measurement"): the standard uncertainty of each input from its
// distribution (clause 4.3), the combined standard uncertainty of uncorrelated inputs (5.1.2),
// the effective degrees of freedom by the Welch-Satterthwaite formula (G.4.1, eq. G.2b) and the
// expanded uncertainty U = k u_c with k from Student's t at nu_eff (G.3, G.4, 6.2).
// Pure functions; no I/O (the budget file's reader is uncertainty/budget_json.h). Stage id
// "uncertainty.budget". docs/uncertainty.md describes the wheel's budget.

#include <limits>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace arcwheel::uncertainty {

inline constexpr double kInfiniteDof = std::numeric_limits<double>::infinity();

// The distribution an input's spread is stated for, and its standard uncertainty u(x):
//   kNormal       spread = U stated with coverage factor k:  u = U / k  (GUM 4.3.3, 4.3.4)
//   kRectangular  spread = half-width a:                      u = a / sqrt(3)  (4.3.7)
//   kTriangular   spread = half-width a:                      u = a / sqrt(6)  (4.3.9)
//   kArcsine      spread = amplitude a (a cyclic variation):  u = a / sqrt(2)  (H.1.3.2)
enum class Distribution { kNormal, kRectangular, kTriangular, kArcsine };

// "normal", "rectangular", "triangular", "arcsine": the names a budget file uses.
[[nodiscard]] std::string_view DistributionName(Distribution distribution);

// How an input was evaluated (GUM 4.2 and 4.3): from readings by statistics, or otherwise.
enum class EvaluationType { kA, kB };

// One input quantity X_i of a measurement model Y = f(X_1, ..., X_N), linearised.
struct Input {
  // Unique in its budget, e.g. "sensor_scale".
  std::string name{};
  // Where the figure comes from (a data sheet, a certificate, the fit), for the reader.
  std::string source{};
  // Unit of `value` and `spread`, e.g. "um", "K", "ppm", "1".
  std::string unit{};
  // Best estimate x_i: the correction it stands for; 0 for an effect that is not corrected.
  double value = 0.0;
  Distribution distribution = Distribution::kNormal;
  // Normal: the uncertainty as stated, with `coverage_factor` (1 = a standard uncertainty).
  // The others: the half-width a of the interval. Finite, >= 0.
  double spread = 0.0;
  // Normal only: the k `spread` was stated with. Finite, > 0.
  double coverage_factor = 1.0;
  // c_i = dY/dX_i, in the output's unit per `unit`. Finite.
  double sensitivity = 1.0;
  // Degrees of freedom nu_i of u(x_i): n - 1 for the mean of n readings (type A), infinite for a
  // type B figure taken as exact (GUM G.4.2), else 1 / (2 (relative uncertainty of u)^2) (G.4.2,
  // eq. G.3). > 0, may be kInfiniteDof.
  double dof = kInfiniteDof;
  EvaluationType type = EvaluationType::kB;

  // Empty when valid, else one line per violation: "<name>.spread = -1 violates >= 0".
  [[nodiscard]] std::vector<std::string> Problems() const;
};

// u(x_i) of `input` by its distribution (see Distribution).
[[nodiscard]] double StandardUncertainty(const Input& input);

// A type A input from repeated readings (GUM 4.2): value = their mean, spread = s / sqrt(n) as a
// standard uncertainty, dof = n - 1. Needs at least two readings (Error{kBadInput} otherwise).
[[nodiscard]] Input TypeAFromReadings(std::string name, std::string unit, std::span<const double> readings,
                                      double sensitivity = 1.0);

// An input standing for a whole sub-budget (its combined u_c and nu_eff), as GUM H.1.3.1 does
// with the measured difference d: a normal input with spread u_c, k = 1 and dof nu_eff.
struct Combined;
[[nodiscard]] Input InputFromCombined(std::string name, std::string unit, const Combined& combined,
                                      double sensitivity = 1.0);

struct CombineOptions {
  // Coverage probability p of the expanded uncertainty. In (0, 1).
  double coverage_probability = 0.95;
  // GUM G.4.1 note 1: t is looked up at nu_eff rounded down to an integer (as H.1.6 does); false
  // looks it up at nu_eff itself.
  bool truncate_dof = true;
  // Empty when valid, else "CombineOptions::coverage_probability = 1.5 violates (0, 1)".
  [[nodiscard]] std::vector<std::string> Problems() const;
};

// One line of the budget table, as GUM table H.1 prints it.
struct Contribution {
  std::string name{};
  double standard_uncertainty = 0.0;  // u(x_i), in the input's unit
  double sensitivity = 0.0;           // c_i
  double contribution = 0.0;          // u_i(y) = |c_i| u(x_i), in the output's unit
  double dof = kInfiniteDof;          // nu_i
};

struct Combined {
  std::vector<Contribution> contributions{};
  // Sum of c_i x_i, the correction the inputs' estimates add to the result (output's unit).
  double correction = 0.0;
  double standard_uncertainty = 0.0;    // u_c(y) = sqrt(sum u_i(y)^2)
  double effective_dof = kInfiniteDof;  // nu_eff by Welch-Satterthwaite, not rounded
  double coverage_probability = 0.95;
  double coverage_factor = 0.0;  // k = t_p(nu_eff)
  double expanded = 0.0;         // U = k u_c
};

// Combines uncorrelated inputs (GUM 5.1.2). No inputs give u_c = 0, nu_eff infinite. Throws
// Error{kInvalidOption, "uncertainty.budget"} listing every problem of the inputs (and names
// repeated) and options.
[[nodiscard]] Combined Combine(std::span<const Input> inputs, const CombineOptions& options = {});

// nu_eff = u_c^4 / sum(u_i^4 / nu_i) with u_c^2 = sum u_i^2 (GUM G.2b); terms of infinite nu_i
// add nothing; infinite when all are. `contributions` are the u_i(y), `dofs` the nu_i, same size.
[[nodiscard]] double WelchSatterthwaite(std::span<const double> contributions, std::span<const double> dofs);

// k such that +- k covers probability p of Student's t with `dof` degrees of freedom (the normal
// distribution when `dof` is infinite): t_p(nu) of GUM table G.2, e.g. (2, 0.95) -> 4.30,
// (16, 0.99) -> 2.92, (inf, 0.95) -> 1.960. With `truncate_dof`, `dof` is rounded down first.
[[nodiscard]] double CoverageFactor(double dof, double probability, bool truncate_dof = true);

}  // namespace arcwheel::uncertainty
