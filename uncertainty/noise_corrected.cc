#include "uncertainty/noise_corrected.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <random>

#include "core/error.h"
#include "core/number_format.h"
#include "core/parallel.h"

namespace arcwheel::uncertainty {
namespace {

constexpr const char* kStage = "uncertainty.pv";

int Functions(SmoothBasis basis, int order) {
  return basis == SmoothBasis::kFourier ? 1 + 2 * order : order + 1;
}

// The basis sampled at the columns, orthonormalised in order (thin Q of a Householder QR), so
// that the fit of each order is the first Functions(order) coefficients of one projection.
Eigen::MatrixXd OrthonormalBasis(SmoothBasis basis, int max_order, int columns) {
  const int n = Functions(basis, max_order);
  Eigen::MatrixXd design(columns, n);
  for (int j = 0; j < columns; ++j) {
    if (basis == SmoothBasis::kFourier) {
      const double c = 2.0 * std::numbers::pi * j / columns;
      design(j, 0) = 1.0;
      for (int k = 1; k <= max_order; ++k) {
        design(j, 2 * k - 1) = std::cos(k * c);
        design(j, 2 * k) = std::sin(k * c);
      }
    } else {
      const double u = columns == 1 ? 0.0 : -1.0 + 2.0 * j / (columns - 1);
      double p0 = 1.0;
      double p1 = u;
      design(j, 0) = p0;
      if (n > 1) design(j, 1) = p1;
      for (int k = 2; k < n; ++k) {
        const double p2 = ((2.0 * k - 1.0) * u * p1 - (k - 1.0) * p0) / k;
        design(j, k) = p2;
        p0 = p1;
        p1 = p2;
      }
    }
  }
  Eigen::HouseholderQR<Eigen::MatrixXd> qr(design);
  Eigen::MatrixXd q = qr.householderQ() * Eigen::MatrixXd::Identity(columns, n);
  // Keep the sign of each function as the design has it (QR may flip it): irrelevant for fits.
  return q;
}

// Fills missing values of a row by linear interpolation; false when fewer than half are present.
bool FillRow(Eigen::Ref<Eigen::VectorXd> row, bool periodic) {
  const int n = static_cast<int>(row.size());
  std::vector<int> present;
  for (int j = 0; j < n; ++j)
    if (std::isfinite(row[j])) present.push_back(j);
  if (2 * static_cast<int>(present.size()) < n || present.empty()) return false;
  if (static_cast<int>(present.size()) == n) return true;
  for (int j = 0; j < n; ++j) {
    if (std::isfinite(row[j])) continue;
    const auto after = std::upper_bound(present.begin(), present.end(), j);
    int right = after == present.end() ? -1 : *after;
    int left = after == present.begin() ? -1 : *(after - 1);
    double right_pos = right;
    double left_pos = left;
    if (periodic) {
      if (right < 0) right = present.front(), right_pos = right + n;
      if (left < 0) left = present.back(), left_pos = left - n;
    } else {
      if (right < 0) right = left, right_pos = left_pos;
      if (left < 0) left = right, left_pos = right_pos;
    }
    const double t = right_pos == left_pos ? 0.0 : (j - left_pos) / (right_pos - left_pos);
    row[j] = (1.0 - t) * row[left] + t * row[right];
  }
  return true;
}

struct Estimate {
  double fitted_pv = 0.0;
  int order = 0;
  double chi2 = 0.0;  // of the data against the fitted rows
  double dof = 0.0;
  Eigen::MatrixXd fitted;  // rows x columns, the rows at the chosen order
};

// The functions of one order: columns [first, first + count) of the basis.
std::pair<int, int> Group(SmoothBasis basis, int order) {
  if (order == 0) return {0, 1};
  return basis == SmoothBasis::kFourier ? std::pair{2 * order - 1, 2} : std::pair{order, 1};
}

// Rows that share a shape (the sections of one wheel) scatter about their mean by noise and by
// their real differences: each coefficient's spread about its mean keeps only its part beyond the
// noise (James-Stein / empirical Bayes shrinkage), so that a maximum over the rows is not taken
// over noise. A coefficient's noise variance is its row's sigma^2 (orthonormal basis).
void ShrinkRows(Eigen::MatrixXd& coefficients, const Eigen::VectorXd& row_sigma,
                const NoiseCorrectedPvOptions& options) {
  const auto rows = coefficients.rows();
  if (!options.shrink_rows || rows <= 2) return;
  const double noise = row_sigma.squaredNorm() / static_cast<double>(rows);
  for (Eigen::Index j = 0; j < coefficients.cols(); ++j) {
    const double mean = coefficients.col(j).mean();
    const double spread = (coefficients.col(j).array() - mean).square().sum() / static_cast<double>(rows - 1);
    const double real = std::max(0.0, spread - noise);
    const double keep = spread > 0.0 ? real / (real + noise) : 0.0;
    coefficients.col(j) = (mean + keep * (coefficients.col(j).array() - mean)).matrix();
  }
}

struct Selection {
  std::vector<int> kept;   // every function kept
  std::vector<int> shown;  // those the PV counts
  int order = 0;           // the highest order the PV counts
};

Selection SelectOrders(const Eigen::MatrixXd& coefficients, const Eigen::VectorXd& row_sigma,
                       const NoiseCorrectedPvOptions& options) {
  Selection selection;
  const auto rows = coefficients.rows();
  for (int order = 0; order <= options.max_order; ++order) {
    const auto [first, count] = Group(options.basis, order);
    double chi2_drop = 0.0;
    for (Eigen::Index r = 0; r < rows; ++r)
      chi2_drop += coefficients.row(r).segment(first, count).squaredNorm() / (row_sigma[r] * row_sigma[r]);
    // An order's functions stay when they lower chi-square by more than noise alone would in
    // five standard deviations of its chi-square (rows x count degrees of freedom); the mean and
    // the orders the PV leaves out always stay.
    const double dof = static_cast<double>(rows) * count;
    const bool always = order == 0 || order < options.pv_from_order;
    if (!always && chi2_drop <= dof + 5.0 * std::sqrt(2.0 * dof)) continue;
    for (int j = first; j < first + count; ++j) {
      selection.kept.push_back(j);
      if (order >= options.pv_from_order) selection.shown.push_back(j);
    }
    if (order >= options.pv_from_order) selection.order = std::max(selection.order, order);
  }
  return selection;
}

// The rows of `columns` of the basis with their coefficients.
Eigen::MatrixXd RowsOf(const Eigen::MatrixXd& coefficients, const Eigen::MatrixXd& q,
                       const std::vector<int>& columns) {
  Eigen::MatrixXd c(coefficients.rows(), static_cast<Eigen::Index>(columns.size()));
  Eigen::MatrixXd basis(q.rows(), static_cast<Eigen::Index>(columns.size()));
  for (std::size_t i = 0; i < columns.size(); ++i) {
    c.col(static_cast<Eigen::Index>(i)) = coefficients.col(columns[i]);
    basis.col(static_cast<Eigen::Index>(i)) = q.col(columns[i]);
  }
  return c * basis.transpose();
}

double LargestRowPv(const Eigen::MatrixXd& coefficients, const Eigen::MatrixXd& q,
                    const std::vector<int>& shown) {
  if (shown.empty()) return 0.0;
  const Eigen::MatrixXd values = RowsOf(coefficients, q, shown);
  double pv = 0.0;
  for (Eigen::Index r = 0; r < values.rows(); ++r)
    pv = std::max(pv, values.row(r).maxCoeff() - values.row(r).minCoeff());
  return pv;
}

// Rows that are neighbours along a smooth coordinate (the map's axial nodes, the sections'
// phases): each kept order's coefficients are fitted along the rows with the across-rows basis
// (Legendre polynomials of the row index, or harmonics over a turn of rows), each of its functions
// kept when it lowers the chi-square of the order's functions by more than noise would in three
// standard deviations (the rows' mean always), so that each row's coefficient carries the noise of
// a few parameters instead of its own.
void SmoothAcrossRows(Eigen::MatrixXd& coefficients, const Eigen::VectorXd& row_sigma,
                      const Selection& selection, const NoiseCorrectedPvOptions& options) {
  const int degree = options.across_rows_max_degree;
  const auto rows = static_cast<int>(coefficients.rows());
  if (degree < 0 || rows < Functions(options.across_rows_basis, degree) + 1) return;
  const Eigen::MatrixXd along = OrthonormalBasis(options.across_rows_basis, degree, rows);
  const double noise = row_sigma.squaredNorm() / rows;  // a coefficient's noise variance, on average
  for (int order = 0; order <= options.max_order; ++order) {
    const auto [first, count] = Group(options.basis, order);
    if (std::find(selection.kept.begin(), selection.kept.end(), first) == selection.kept.end()) continue;
    const Eigen::MatrixXd a = along.transpose() * coefficients.middleCols(first, count);  // degrees x count
    Eigen::MatrixXd smooth = Eigen::MatrixXd::Zero(rows, count);
    for (Eigen::Index d = 0; d < along.cols(); ++d) {
      const double drop = a.row(d).squaredNorm() / noise;
      if (d > 0 && drop <= count + 3.0 * std::sqrt(2.0 * count)) continue;
      smooth += along.col(d) * a.row(d);
    }
    coefficients.middleCols(first, count) = smooth;
  }
}

// The estimate from the rows' raw coefficients on the basis (data times q): shrunk, orders
// chosen, smoothed across the rows when asked, the PV of the shown orders.
Estimate FromCoefficients(Eigen::MatrixXd coefficients, const Eigen::VectorXd& row_sigma,
                          const Eigen::MatrixXd& q, const NoiseCorrectedPvOptions& options,
                          Eigen::MatrixXd* kept_coefficients = nullptr) {
  ShrinkRows(coefficients, row_sigma, options);
  const Selection selection = SelectOrders(coefficients, row_sigma, options);
  SmoothAcrossRows(coefficients, row_sigma, selection, options);
  Estimate estimate;
  estimate.order = selection.order;
  estimate.fitted_pv = LargestRowPv(coefficients, q, selection.shown);
  if (kept_coefficients != nullptr) {
    *kept_coefficients = Eigen::MatrixXd::Zero(coefficients.rows(), coefficients.cols());
    for (const int j : selection.kept) kept_coefficients->col(j) = coefficients.col(j);
  }
  return estimate;
}

// The estimate on data `y` (rows x columns, complete rows) with per-row noise sigma `row_sigma`,
// with the fitted rows, their coefficients and the chi-square of the data against them.
Estimate Fit(const Eigen::MatrixXd& y, const Eigen::VectorXd& row_sigma, const Eigen::MatrixXd& q,
             const NoiseCorrectedPvOptions& options, Eigen::MatrixXd& kept_coefficients) {
  Estimate estimate = FromCoefficients(y * q, row_sigma, q, options, &kept_coefficients);
  estimate.fitted = kept_coefficients * q.transpose();
  const Eigen::MatrixXd residual = y - estimate.fitted;
  for (Eigen::Index r = 0; r < y.rows(); ++r)
    estimate.chi2 += residual.row(r).squaredNorm() / (row_sigma[r] * row_sigma[r]);
  const auto kept = static_cast<double>((kept_coefficients.colwise().squaredNorm().array() > 0.0).count());
  estimate.dof = static_cast<double>(y.size()) - static_cast<double>(y.rows()) * kept;
  return estimate;
}

// True when every row's sigmas are one value: the noise of the row's coefficients on the
// orthonormal basis is then that sigma times independent standard normals.
bool SigmaConstantAlongRows(const Eigen::MatrixXd& sigma) {
  for (Eigen::Index r = 0; r < sigma.rows(); ++r) {
    const double first = sigma(r, 0);
    if ((sigma.row(r).array() - first).abs().maxCoeff() > 1e-12 * std::abs(first)) return false;
  }
  return true;
}

}  // namespace

std::vector<std::string> NoiseCorrectedPvOptions::Problems() const {
  std::vector<std::string> problems;
  const auto rule = [&](bool ok, const char* name, double value, const char* text) {
    if (!ok)
      problems.push_back(std::string("NoiseCorrectedPvOptions::") + name + " = " + ShowSignificant(value) +
                         " violates " + text);
  };
  rule(max_order >= 0, "max_order", max_order, ">= 0");
  rule(pv_from_order >= 0 && pv_from_order <= max_order, "pv_from_order", pv_from_order, "0..max_order");
  rule(replicates >= 20, "replicates", replicates, ">= 20");
  return problems;
}

NoiseCorrectedPv EstimateNoiseCorrectedPv(std::span<const double> values, std::span<const double> sigmas,
                                          int rows, int columns, const NoiseCorrectedPvOptions& options) {
  ThrowIfProblems(ErrorCode::kInvalidOption, kStage, options.Problems());
  if (rows <= 0 || columns <= 0 || values.size() != static_cast<std::size_t>(rows) * columns ||
      sigmas.size() != values.size()) {
    throw Error(ErrorCode::kBadInput, kStage,
                std::to_string(values.size()) + " values and " + std::to_string(sigmas.size()) +
                    " sigmas for " + std::to_string(rows) + " x " + std::to_string(columns));
  }
  if (Functions(options.basis, options.max_order) >= columns) {
    throw Error(ErrorCode::kInvalidOption, kStage,
                "NoiseCorrectedPvOptions::max_order = " + std::to_string(options.max_order) + " violates < " +
                    std::to_string(columns) + " functions for a row of " + std::to_string(columns));
  }
  const bool periodic = options.basis == SmoothBasis::kFourier;
  std::vector<int> kept;
  Eigen::MatrixXd all(rows, columns);
  Eigen::MatrixXd all_sigma(rows, columns);
  NoiseCorrectedPv result;
  for (int r = 0; r < rows; ++r) {
    double low = std::numeric_limits<double>::infinity();
    double high = -low;
    for (int j = 0; j < columns; ++j) {
      const double v = values[static_cast<std::size_t>(r) * columns + j];
      const double s = sigmas[static_cast<std::size_t>(r) * columns + j];
      const bool present = std::isfinite(v) && std::isfinite(s) && s > 0.0;
      all(r, j) = present ? v : std::numeric_limits<double>::quiet_NaN();
      all_sigma(r, j) = present ? s : std::numeric_limits<double>::quiet_NaN();
      if (present) low = std::min(low, v), high = std::max(high, v);
    }
    Eigen::VectorXd row = all.row(r).transpose();
    if (FillRow(row, periodic)) {
      all.row(r) = row.transpose();
      Eigen::VectorXd sigma_row = all_sigma.row(r).transpose();
      FillRow(sigma_row, periodic);
      all_sigma.row(r) = sigma_row.transpose();
      kept.push_back(r);
      result.raw_pv = std::max(result.raw_pv, high - low);
    }
  }
  if (kept.empty()) throw Error(ErrorCode::kBadInput, kStage, "no row has half its values present");
  const int n_rows = static_cast<int>(kept.size());
  Eigen::MatrixXd y(n_rows, columns);
  Eigen::MatrixXd sigma(n_rows, columns);
  Eigen::VectorXd row_sigma(n_rows);
  for (int i = 0; i < n_rows; ++i) {
    y.row(i) = all.row(kept[i]);
    sigma.row(i) = all_sigma.row(kept[i]);
    row_sigma[i] = std::sqrt(sigma.row(i).squaredNorm() / columns);
  }
  const Eigen::MatrixXd q = OrthonormalBasis(options.basis, options.max_order, columns);
  Eigen::MatrixXd kept_coefficients;
  Estimate estimate = Fit(y, row_sigma, q, options, kept_coefficients);
  // The noise as the data show it: the sigmas scaled by the root of chi-square per degree of
  // freedom of the fit (Birge ratio), then the fit repeated with them.
  if (options.sigmas_from_residuals && estimate.dof > 0.0 && estimate.chi2 > 0.0) {
    result.sigma_scale = std::sqrt(estimate.chi2 / estimate.dof);
    sigma *= result.sigma_scale;
    row_sigma *= result.sigma_scale;
    estimate = Fit(y, row_sigma, q, options, kept_coefficients);
  }
  result.fitted_pv = estimate.fitted_pv;
  result.order = estimate.order;
  result.rows_used = n_rows;
  result.replicates = options.replicates;

  // Each data set is the fitted rows plus normal noise of each value's sigma. Where the sigma is
  // one value along each row (the map's rows), the noise of the row's coefficients is drawn
  // instead: the same distribution (the basis is orthonormal), with a few dozen draws a row
  // instead of one a value. Each replicate has its own random stream (the seed and its number),
  // so the result does not depend on how the replicates are shared between the two workers.
  const bool draw_coefficients = SigmaConstantAlongRows(sigma);
  const Eigen::Index functions = q.cols();
  std::vector<double> pv(static_cast<std::size_t>(options.replicates));
  RunOnWorkers(2, [&](int worker) {
    for (int b = worker; b < options.replicates; b += 2) {
      std::seed_seq seeds{options.seed, static_cast<std::uint64_t>(b)};
      std::mt19937_64 rng(seeds);
      std::normal_distribution<double> normal(0.0, 1.0);
      Eigen::MatrixXd coefficients;
      if (draw_coefficients) {
        coefficients = kept_coefficients;
        for (Eigen::Index j = 0; j < functions; ++j)
          for (Eigen::Index i = 0; i < n_rows; ++i) coefficients(i, j) += row_sigma[i] * normal(rng);
      } else {
        Eigen::MatrixXd replicate(n_rows, columns);
        for (Eigen::Index j = 0; j < columns; ++j)
          for (Eigen::Index i = 0; i < n_rows; ++i)
            replicate(i, j) = estimate.fitted(i, j) + sigma(i, j) * normal(rng);
        coefficients = replicate * q;
      }
      pv[static_cast<std::size_t>(b)] =
          FromCoefficients(std::move(coefficients), row_sigma, q, options).fitted_pv;
    }
  });
  double sum = 0.0;
  double sum_squares = 0.0;
  for (const double x : pv) {
    sum += x;
    sum_squares += x * x;
  }
  const double n = options.replicates;
  const double mean = sum / n;
  result.bias = mean - result.fitted_pv;
  result.value = std::max(0.0, result.fitted_pv - result.bias);  // a PV is never negative
  result.standard_uncertainty = std::sqrt(std::max(0.0, (sum_squares - n * mean * mean) / (n - 1.0)));
  return result;
}

}  // namespace arcwheel::uncertainty
