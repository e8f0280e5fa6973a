#include "uncertainty/noise_corrected.h"

#include <Eigen/Dense>
#include <algorithm>
#include <boost/random/mersenne_twister.hpp>
#include <boost/random/normal_distribution.hpp>
#include <cmath>
#include <limits>
#include <map>
#include <mutex>
#include <numbers>
#include <random>
#include <tuple>

#include "core/dense.h"
#include "core/error.h"
#include "core/number_format.h"
#include "core/parallel.h"

namespace arcwheel::uncertainty {
namespace {

constexpr const char* kNoiseCorrectedStage = "uncertainty.pv";

int Functions(SmoothBasis basis, int order) {
  return basis == SmoothBasis::kFourier ? 1 + 2 * order : order + 1;
}

// The basis's functions at `positions` (column indices over a turn for kFourier, u in [-1, 1]
// for kLegendre): positions x Functions(basis, max_order).
Eigen::MatrixXd Design(SmoothBasis basis, int max_order, const Eigen::VectorXd& positions, int columns) {
  const int n = Functions(basis, max_order);
  Eigen::MatrixXd design(positions.size(), n);
  for (Eigen::Index j = 0; j < positions.size(); ++j) {
    if (basis == SmoothBasis::kFourier) {
      const double c = 2.0 * std::numbers::pi * positions[j] / columns;
      design(j, 0) = 1.0;
      for (int k = 1; k <= max_order; ++k) {
        design(j, 2 * k - 1) = std::cos(k * c);
        design(j, 2 * k) = std::sin(k * c);
      }
    } else {
      const double u = positions[j];
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
  return design;
}

// Positions of `columns` equally spaced columns: indices over a turn, or u over [-1, 1].
Eigen::VectorXd EvenPositions(SmoothBasis basis, int columns) {
  Eigen::VectorXd positions(columns);
  for (int j = 0; j < columns; ++j)
    positions[j] = basis == SmoothBasis::kFourier ? j : (columns == 1 ? 0.0 : -1.0 + 2.0 * j / (columns - 1));
  return positions;
}

// The basis at `columns` equally spaced columns, orthonormalised in order (thin Q of a Householder
// QR), so that the fit of each order is the first Functions(order) coefficients of one projection.
// Made once a process for each (basis, order, columns): a scan asks for the same few, a turn's
// Fourier basis five times and the across-rows basis in every bootstrap replicate, and each QR
// cost some 5 ms of a 1e6-sample scan's processing (made in each replicate, the across-rows bases
// took the arc error's bootstrap from 0.032 s to 0.080 s).
const Eigen::MatrixXd& OrthonormalBasis(SmoothBasis basis, int max_order, int columns) {
  static std::mutex mutex;
  static std::map<std::tuple<SmoothBasis, int, int>, Eigen::MatrixXd> made;  // its nodes never move
  const std::lock_guard<std::mutex> lock(mutex);
  const auto [found, inserted] = made.try_emplace({basis, max_order, columns});
  if (inserted)
    found->second = dense::HouseholderThinQ(Design(basis, max_order, EvenPositions(basis, columns), columns));
  return found->second;
}

// Points over [-1, 1] at which a positioned row's PV is taken: the fitted function over the
// whole interval, so that the PV does not depend on how near the edges a row's points happen to
// fall.
constexpr int kPvGridPoints = 401;

// The basis each row is fitted on, and the fits and rows it gives.
//  - Shared: every row's values sit at the same equally spaced columns; one orthonormal basis Q.
//  - Positioned (Legendre): each value has a position of its own (a section's points lie where the
//    helix crossed the phase). Every row is fitted (least squares) on the Legendre polynomials of
//    the interval itself, each scaled to a unit sum of squares over as many evenly spread points
//    as a row has columns: a coefficient is the same function of position in every row (the rows'
//    fits can be smoothed along the rows), an order is the interval's (a P4 profile is order 4
//    alone, wherever a row's points fall; a basis orthonormal over a row's points would spread it
//    over the orders below, which the choice of orders then drops by chance), and the basis is
//    orthonormal to within the points' unevenness. Missing values take no part (their rows of the
//    design are zero). The PV is of the fitted function over [-1, 1].
class RowBases {
 public:
  explicit RowBases(Eigen::MatrixXd q) : shared_(std::move(q)) {}
  RowBases(int max_order, const Eigen::MatrixXd& positions, const Eigen::MatrixXd& present) {
    const Eigen::Index rows = positions.rows(), columns = positions.cols();
    const auto design = [&](const Eigen::VectorXd& u) {
      return Design(SmoothBasis::kLegendre, max_order, u, static_cast<int>(columns));
    };
    // P_k scaled to a unit sum of squares over `columns` points spread evenly over [-1, 1] (the
    // mean of P_k^2 over the interval is 1 / (2k + 1)).
    Eigen::VectorXd scale(max_order + 1);
    for (int k = 0; k <= max_order; ++k) scale[k] = std::sqrt((2.0 * k + 1.0) / static_cast<double>(columns));
    for (Eigen::Index i = 0; i < rows; ++i) {
      Eigen::MatrixXd e = design(positions.row(i).transpose()) * scale.asDiagonal();
      for (Eigen::Index j = 0; j < columns; ++j)
        if (present(i, j) == 0.0) e.row(j).setZero();
      fit_.emplace_back(dense::LdltSolve(e.transpose() * e, Eigen::MatrixXd(e.transpose())));
      eval_.push_back(std::move(e));
    }
    grid_ = design(EvenPositions(SmoothBasis::kLegendre, kPvGridPoints)) * scale.asDiagonal();
  }

  [[nodiscard]] bool shared() const { return eval_.empty(); }
  [[nodiscard]] Eigen::Index functions() const { return shared() ? shared_.cols() : grid_.cols(); }

  // rows x functions: each row's least-squares coefficients (missing values are 0 in `y`).
  [[nodiscard]] Eigen::MatrixXd Coefficients(const Eigen::MatrixXd& y) const {
    if (shared()) return y * shared_;
    Eigen::MatrixXd c(y.rows(), functions());
    for (Eigen::Index i = 0; i < y.rows(); ++i) c.row(i) = (fit_[i] * y.row(i).transpose()).transpose();
    return c;
  }

  // rows x columns: the fitted rows at the values' columns or positions (0 where one is missing).
  [[nodiscard]] Eigen::MatrixXd Rows(const Eigen::MatrixXd& coefficients) const {
    if (shared()) return coefficients * shared_.transpose();
    Eigen::MatrixXd values(coefficients.rows(), eval_.front().rows());
    for (Eigen::Index i = 0; i < coefficients.rows(); ++i)
      values.row(i) = (eval_[i] * coefficients.row(i).transpose()).transpose();
    return values;
  }

  // The rows of the functions `which` alone, where the PV is taken: at the columns (shared) or
  // over the grid (positioned), one row to a column of the result, so that each row's extremes
  // are read from contiguous memory.
  [[nodiscard]] Eigen::MatrixXd PvRowsAsColumns(const Eigen::MatrixXd& coefficients,
                                                const std::vector<int>& which) const {
    const Eigen::MatrixXd& basis = shared() ? shared_ : grid_;
    const auto n = static_cast<Eigen::Index>(which.size());
    Eigen::MatrixXd c(coefficients.rows(), n), b(basis.rows(), n);
    for (Eigen::Index k = 0; k < n; ++k) {
      c.col(k) = coefficients.col(which[k]);
      b.col(k) = basis.col(which[k]);
    }
    return b * c.transpose();
  }

 private:
  Eigen::MatrixXd shared_;
  std::vector<Eigen::MatrixXd> eval_, fit_;
  Eigen::MatrixXd grid_;
};

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
  std::vector<int> kept_in_full;  // the functions of the orders kept at full weight, ascending
  bool shows_an_order_in_full = false;
  double world_pv = 0.0;  // the PV with the orders kept in part at full weight
  double chi2 = 0.0;      // of the data against the fitted rows
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
  std::vector<int> kept;                        // every function kept
  std::vector<int> shown;                       // those the PV counts
  std::vector<int> kept_in_full;                // those kept at full weight
  std::vector<std::pair<int, double>> partial;  // (order, weight < 1) of the orders kept in part
  int order = 0;                                // the highest order the PV counts
  bool shows_an_order_in_full = false;          // an order the PV counts, not the mean, at full weight
};

// An order whose functions lower the chi-square by z standard deviations of noise's chi-square
// beyond its mean counts with weight 0 up to z = 5, 1 from z = 7, and linearly in between, so that
// the PV does not jump when an order crosses one cut. Only the orders kept in full are held fixed
// when the uncertainty is taken (StandardUncertainty); an order on the edge, noise that happens to
// pass or a real order that barely does, is weighed in every replicate anew, and its flips count
// in the spread. With a hard cut at 5 and the same uncertainty, the centre deviation's intervals
// covered 90.0 % over the coverage test's 200 scans; with the ramp, 94.5 %.
constexpr double kKeepFromSd = 5.0;
constexpr double kKeepInFullFromSd = 7.0;

double KeepWeight(double chi2_drop, double dof) {
  const double z = (chi2_drop - dof) / std::sqrt(2.0 * dof);
  return std::clamp((z - kKeepFromSd) / (kKeepInFullFromSd - kKeepFromSd), 0.0, 1.0);
}

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
    // five standard deviations of its chi-square (rows x count degrees of freedom), in full from
    // seven (KeepWeight); the mean and the orders the PV leaves out always stay.
    const double dof = static_cast<double>(rows) * count;
    const bool always = order == 0 || order < options.pv_from_order;
    const double weight = always ? 1.0 : KeepWeight(chi2_drop, dof);
    if (weight <= 0.0) continue;
    if (weight < 1.0) selection.partial.emplace_back(order, weight);
    if (weight == 1.0 && !always) selection.shows_an_order_in_full = true;
    for (int j = first; j < first + count; ++j) {
      selection.kept.push_back(j);
      if (weight == 1.0) selection.kept_in_full.push_back(j);
      if (order >= options.pv_from_order) selection.shown.push_back(j);
    }
    if (order >= options.pv_from_order) selection.order = std::max(selection.order, order);
  }
  return selection;
}

double LargestRowPv(const Eigen::MatrixXd& coefficients, const RowBases& bases,
                    const std::vector<int>& shown) {
  if (shown.empty()) return 0.0;
  const Eigen::MatrixXd values = bases.PvRowsAsColumns(coefficients, shown);
  return std::max(0.0, (values.colwise().maxCoeff() - values.colwise().minCoeff()).maxCoeff());
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
  const Eigen::MatrixXd& along = OrthonormalBasis(options.across_rows_basis, degree, rows);
  const double noise = row_sigma.squaredNorm() / rows;  // a coefficient's noise variance, on average
  for (int order = 0; order <= options.max_order; ++order) {
    const auto [first, count] = Group(options.basis, order);
    if (std::find(selection.kept.begin(), selection.kept.end(), first) == selection.kept.end()) continue;
    const Eigen::MatrixXd a = along.transpose() * coefficients.middleCols(first, count);  // degrees x count
    Eigen::MatrixXd smooth = Eigen::MatrixXd::Zero(rows, count);
    for (Eigen::Index d = 0; d < along.cols(); ++d) {
      const double drop = a.row(d).squaredNorm() / noise;
      if (d > 0 && drop <= count + options.across_rows_keep_sd * std::sqrt(2.0 * count)) continue;
      smooth += along.col(d) * a.row(d);
    }
    coefficients.middleCols(first, count) = smooth;
  }
}

// The estimate from the rows' raw coefficients on the basis: shrunk, orders chosen, smoothed
// across the rows when asked, the PV of the shown orders.
Estimate FromCoefficients(Eigen::MatrixXd coefficients, const Eigen::VectorXd& row_sigma,
                          const RowBases& bases, const NoiseCorrectedPvOptions& options,
                          Eigen::MatrixXd* kept_coefficients = nullptr) {
  ShrinkRows(coefficients, row_sigma, options);
  const Selection selection = SelectOrders(coefficients, row_sigma, options);
  SmoothAcrossRows(coefficients, row_sigma, selection, options);
  Estimate estimate;
  estimate.order = selection.order;
  estimate.kept_in_full = selection.kept_in_full;
  estimate.shows_an_order_in_full = selection.shows_an_order_in_full;
  // The bootstrap's world holds the orders kept in part at their full fitted size: the weight is
  // the estimator's, and the bias the replicates find then includes what it takes off a real order
  // on the edge (drawn from the weighted fit, the replicates would lose that order more often still,
  // and the bias would miss it: a runout 0.03 um, 2.4 U, low on the regression scan with dropouts).
  if (kept_coefficients != nullptr) {
    *kept_coefficients = Eigen::MatrixXd::Zero(coefficients.rows(), coefficients.cols());
    for (const int j : selection.kept) kept_coefficients->col(j) = coefficients.col(j);
    estimate.world_pv = LargestRowPv(coefficients, bases, selection.shown);
  }
  if (kept_coefficients != nullptr && selection.partial.empty()) {
    estimate.fitted_pv = estimate.world_pv;  // no order kept in part: the same rows
    return estimate;
  }
  for (const auto& [order, weight] : selection.partial) {
    const auto [first, count] = Group(options.basis, order);
    coefficients.middleCols(first, count) *= weight;
  }
  estimate.fitted_pv = LargestRowPv(coefficients, bases, selection.shown);
  return estimate;
}

// The estimate on data `y` (rows x columns; missing values 0, as `bases` marks them) with per-row
// noise sigma `row_sigma`, with the fitted rows, their coefficients and the chi-square of the data
// against them.
Estimate Fit(const Eigen::MatrixXd& y, const Eigen::VectorXd& row_sigma, double present,
             const RowBases& bases, const NoiseCorrectedPvOptions& options,
             Eigen::MatrixXd& kept_coefficients) {
  Estimate estimate = FromCoefficients(bases.Coefficients(y), row_sigma, bases, options, &kept_coefficients);
  estimate.fitted = bases.Rows(kept_coefficients);
  for (Eigen::Index r = 0; r < y.rows(); ++r)
    estimate.chi2 += (y.row(r) - estimate.fitted.row(r)).squaredNorm() / (row_sigma[r] * row_sigma[r]);
  const auto kept = static_cast<double>((kept_coefficients.colwise().squaredNorm().array() > 0.0).count());
  estimate.dof = present - static_cast<double>(y.rows()) * kept;
  return estimate;
}

double StandardDeviation(const std::vector<double>& x) {
  if (x.size() < 2) return 0.0;
  const Eigen::Map<const Eigen::ArrayXd> a(x.data(), static_cast<Eigen::Index>(x.size()));
  return std::sqrt((a - a.mean()).square().sum() / static_cast<double>(x.size() - 1));
}

// The standard deviation of the replicates' PVs that keep in full just the orders the data keep in
// full: the uncertainty of the PV of the orders the data show, given that they show them. A
// replicate that loses a real order has a PV far below the rest, and the replicates of data whose
// real orders happen to come out low lose them far more often than measurements of the wheel do
// (the bootstrap of a choice at a threshold is not consistent there), so the spread of all
// replicates overstates the estimate's scatter. A replicate that takes in an order of noise besides
// has a PV above the rest for the same reason, and letting those in overstated u by about 16 % on
// the scans whose fit keeps only the real orders (docs/uncertainty.md). When the data show no order
// in full (nothing beyond noise but on the edge), or fewer than half of the replicates keep the
// data's orders, the choice itself is what is uncertain, and the spread of all replicates is the
// honest one: held to the replicates that find nothing too, a PV of noise alone would be 0 +- 0.
// The bias is that of all replicates, noise orders taken in included.
double StandardUncertainty(const std::vector<double>& pv, const std::vector<char>& keeps_the_data_orders) {
  std::vector<double> kept;
  for (std::size_t b = 0; b < pv.size(); ++b)
    if (keeps_the_data_orders[b] != 0) kept.push_back(pv[b]);
  return 2 * kept.size() >= pv.size() ? StandardDeviation(kept) : StandardDeviation(pv);
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
  rule(across_rows_keep_sd > 0.0, "across_rows_keep_sd", across_rows_keep_sd, "> 0");
  return problems;
}

namespace {

void CheckShapes(std::span<const double> values, std::span<const double> sigmas, int rows, int columns,
                 const NoiseCorrectedPvOptions& options) {
  ThrowIfProblems(ErrorCode::kInvalidOption, kNoiseCorrectedStage, options.Problems());
  if (rows <= 0 || columns <= 0 || values.size() != static_cast<std::size_t>(rows) * columns ||
      sigmas.size() != values.size()) {
    throw Error(ErrorCode::kBadInput, kNoiseCorrectedStage,
                std::to_string(values.size()) + " values and " + std::to_string(sigmas.size()) +
                    " sigmas for " + std::to_string(rows) + " x " + std::to_string(columns));
  }
  if (Functions(options.basis, options.max_order) >= columns) {
    throw Error(ErrorCode::kInvalidOption, kNoiseCorrectedStage,
                "NoiseCorrectedPvOptions::max_order = " + std::to_string(options.max_order) + " violates < " +
                    std::to_string(columns) + " functions for a row of " + std::to_string(columns));
  }
}

// The rows that are used, their values (0 where missing), sigmas (0 where missing) and positions.
struct Rows {
  Eigen::MatrixXd y, sigma, positions, present;
  Eigen::VectorXd row_sigma;  // root mean square of each row's present sigmas
  std::vector<int> used;      // each row's index in the caller's rows
  int given_rows = 0;         // the caller's rows
  double values = 0.0;        // present values
  double raw_pv = 0.0;
};

bool Present(double v, double s) { return std::isfinite(v) && std::isfinite(s) && s > 0.0; }

void SetRowSigmas(Rows& rows) {
  rows.row_sigma.resize(rows.y.rows());
  for (Eigen::Index i = 0; i < rows.y.rows(); ++i) {
    const double n = rows.present.size() > 0 ? rows.present.row(i).sum() : static_cast<double>(rows.y.cols());
    rows.row_sigma[i] = std::sqrt(rows.sigma.row(i).squaredNorm() / n);
    rows.values += n;
  }
}

// Values at the columns: a missing value is filled along its row; a row with fewer than half its
// values present is left out.
Rows FilledRows(std::span<const double> values, std::span<const double> sigmas, int rows, int columns,
                bool periodic) {
  std::vector<Eigen::VectorXd> y_rows, sigma_rows;
  Rows out;
  out.given_rows = rows;
  for (int r = 0; r < rows; ++r) {
    Eigen::VectorXd row(columns), sigma_row(columns);
    double low = std::numeric_limits<double>::infinity(), high = -low;
    for (int j = 0; j < columns; ++j) {
      const double v = values[static_cast<std::size_t>(r) * columns + j];
      const double s = sigmas[static_cast<std::size_t>(r) * columns + j];
      const bool present = Present(v, s);
      row[j] = present ? v : std::numeric_limits<double>::quiet_NaN();
      sigma_row[j] = present ? s : std::numeric_limits<double>::quiet_NaN();
      if (present) low = std::min(low, v), high = std::max(high, v);
    }
    if (!FillRow(row, periodic)) continue;
    FillRow(sigma_row, periodic);
    out.used.push_back(r);
    y_rows.push_back(std::move(row));
    sigma_rows.push_back(std::move(sigma_row));
    out.raw_pv = std::max(out.raw_pv, high - low);
  }
  if (y_rows.empty())
    throw Error(ErrorCode::kBadInput, kNoiseCorrectedStage, "no row has half its values present");
  const auto n = static_cast<Eigen::Index>(y_rows.size());
  out.y.resize(n, columns);
  out.sigma.resize(n, columns);
  for (Eigen::Index i = 0; i < n; ++i) {
    out.y.row(i) = y_rows[i].transpose();
    out.sigma.row(i) = sigma_rows[i].transpose();
  }
  SetRowSigmas(out);
  return out;
}

// Values at positions of their own: a missing one is left out; a row with fewer than half its
// values present, or no more than the basis has functions, is left out.
Rows PositionedRows(std::span<const double> values, std::span<const double> sigmas,
                    std::span<const double> positions, int rows, int columns, int functions) {
  std::vector<int> used;
  Rows out;
  out.given_rows = rows;
  for (int r = 0; r < rows; ++r) {
    int present = 0;
    double low = std::numeric_limits<double>::infinity(), high = -low;
    for (int j = 0; j < columns; ++j) {
      const std::size_t k = static_cast<std::size_t>(r) * columns + j;
      if (!Present(values[k], sigmas[k]) || !std::isfinite(positions[k])) continue;
      ++present;
      low = std::min(low, values[k]), high = std::max(high, values[k]);
    }
    if (2 * present < columns || present <= functions) continue;
    used.push_back(r);
    out.raw_pv = std::max(out.raw_pv, high - low);
  }
  if (used.empty())
    throw Error(ErrorCode::kBadInput, kNoiseCorrectedStage, "no row has half its values present");
  const auto n = static_cast<Eigen::Index>(used.size());
  out.used = used;
  out.y = out.sigma = out.present = Eigen::MatrixXd::Zero(n, columns);
  out.positions = Eigen::MatrixXd::Zero(n, columns);
  for (Eigen::Index i = 0; i < n; ++i) {
    for (int j = 0; j < columns; ++j) {
      const std::size_t k = static_cast<std::size_t>(used[i]) * columns + j;
      if (!Present(values[k], sigmas[k]) || !std::isfinite(positions[k])) continue;
      out.y(i, j) = values[k];
      out.sigma(i, j) = sigmas[k];
      out.positions(i, j) = positions[k];
      out.present(i, j) = 1.0;
    }
  }
  SetRowSigmas(out);
  return out;
}

// The rows the bootstrap draws about (the fit with its orders kept in part at full size), laid
// out as the caller's rows: NaN where a value is missing or its row is left out.
std::vector<double> WorldRows(const Rows& data, const Eigen::MatrixXd& fitted, SmoothBasis basis) {
  const auto columns = data.y.cols();
  const std::size_t total = static_cast<std::size_t>(data.given_rows) * columns;
  std::vector<double> out(total, std::numeric_limits<double>::quiet_NaN());
  const bool positioned = data.present.size() > 0 && basis == SmoothBasis::kLegendre;
  for (std::size_t i = 0; i < data.used.size(); ++i) {
    const auto r = static_cast<Eigen::Index>(i);
    for (Eigen::Index j = 0; j < columns; ++j)
      if (!positioned || data.present(r, j) != 0.0)
        out[static_cast<std::size_t>(data.used[i]) * columns + j] = fitted(r, j);
  }
  return out;
}

// The fit of the rows, and its repetition with the sigmas scaled by the root of chi-square per
// degree of freedom of the first (Birge ratio, into `sigma_scale`) when the noise is taken as the
// data show it: `data`'s sigmas are scaled with it.
Estimate FitWithDataSigmas(Rows& data, const RowBases& bases, const NoiseCorrectedPvOptions& options,
                           Eigen::MatrixXd& kept_coefficients, double& sigma_scale) {
  Estimate estimate = Fit(data.y, data.row_sigma, data.values, bases, options, kept_coefficients);
  sigma_scale = 1.0;
  if (options.sigmas_from_residuals && estimate.dof > 0.0 && estimate.chi2 > 0.0) {
    sigma_scale = std::sqrt(estimate.chi2 / estimate.dof);
    data.sigma *= sigma_scale;
    data.row_sigma *= sigma_scale;
    estimate = Fit(data.y, data.row_sigma, data.values, bases, options, kept_coefficients);
  }
  return estimate;
}

// The estimate and its bootstrap on rows gathered by FilledRows or PositionedRows.
NoiseCorrectedPv Solve(Rows data, const RowBases& bases, const NoiseCorrectedPvOptions& options) {
  NoiseCorrectedPv result;
  result.raw_pv = data.raw_pv;
  Eigen::MatrixXd& sigma = data.sigma;
  Eigen::VectorXd& row_sigma = data.row_sigma;
  const auto n_rows = data.y.rows();
  const auto columns = data.y.cols();
  Eigen::MatrixXd kept_coefficients;
  const Estimate estimate = FitWithDataSigmas(data, bases, options, kept_coefficients, result.sigma_scale);
  result.fitted_pv = estimate.fitted_pv;
  result.fitted_rows = WorldRows(data, estimate.fitted, options.basis);
  result.order = estimate.order;
  result.rows_used = static_cast<int>(n_rows);
  result.replicates = options.replicates;

  // Each data set is the fitted rows plus normal noise of each value's sigma. Where the sigma is
  // one value along each row on a shared basis (the map's rows), the noise of the row's
  // coefficients is drawn instead: the same distribution (the basis is orthonormal), with a few
  // dozen draws a row instead of one a value. Each replicate has its own random stream (the seed
  // and its number), so the result does not depend on how the replicates are shared between the
  // two workers.
  const bool draw_coefficients = bases.shared() && SigmaConstantAlongRows(sigma);
  const Eigen::Index functions = bases.functions();
  std::vector<double> pv(static_cast<std::size_t>(options.replicates));
  std::vector<char> keeps_the_data_orders(pv.size(), 0);
  RunOnWorkers(2, [&](int worker) {
    for (int b = worker; b < options.replicates; b += 2) {
      std::seed_seq seeds{options.seed, static_cast<std::uint64_t>(b)};
      // Boost's Mersenne Twister: the standard's mt19937_64 stream to the bit, but its state refill
      // has no branch on a random bit (the standard library's mispredicted every other word).
      boost::random::mt19937_64 rng(seeds);
      // Boost's ziggurat: standard normal deviates at less than half the cost of the standard
      // library's polar method, which took a fifth of a 1e7-sample scan's processing.
      boost::random::normal_distribution<double> normal(0.0, 1.0);
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
        coefficients = bases.Coefficients(replicate);
      }
      const Estimate replica = FromCoefficients(std::move(coefficients), row_sigma, bases, options);
      pv[static_cast<std::size_t>(b)] = replica.fitted_pv;
      keeps_the_data_orders[static_cast<std::size_t>(b)] =
          !estimate.shows_an_order_in_full || replica.kept_in_full == estimate.kept_in_full;
    }
  });
  const double mean =
      Eigen::Map<const Eigen::ArrayXd>(pv.data(), static_cast<Eigen::Index>(pv.size())).mean();
  result.bias = mean - estimate.world_pv;
  result.value = std::max(0.0, result.fitted_pv - result.bias);  // a PV is never negative
  result.standard_uncertainty = StandardUncertainty(pv, keeps_the_data_orders);
  result.dof = options.replicates - 1.0;
  return result;
}

}  // namespace

NoiseCorrectedPv EstimateNoiseCorrectedPv(std::span<const double> values, std::span<const double> sigmas,
                                          int rows, int columns, const NoiseCorrectedPvOptions& options) {
  CheckShapes(values, sigmas, rows, columns, options);
  Rows data = FilledRows(values, sigmas, rows, columns, options.basis == SmoothBasis::kFourier);
  const RowBases bases(OrthonormalBasis(options.basis, options.max_order, columns));
  return Solve(std::move(data), bases, options);
}

std::vector<double> FitNoiseFreeRows(std::span<const double> values, std::span<const double> sigmas, int rows,
                                     int columns, const NoiseCorrectedPvOptions& options) {
  CheckShapes(values, sigmas, rows, columns, options);
  Rows data = FilledRows(values, sigmas, rows, columns, options.basis == SmoothBasis::kFourier);
  const RowBases bases(OrthonormalBasis(options.basis, options.max_order, columns));
  Eigen::MatrixXd kept_coefficients;
  double sigma_scale = 1.0;
  const Estimate estimate = FitWithDataSigmas(data, bases, options, kept_coefficients, sigma_scale);
  return WorldRows(data, estimate.fitted, options.basis);
}

NoiseCorrectedPv EstimateNoiseCorrectedPv(std::span<const double> values, std::span<const double> sigmas,
                                          std::span<const double> positions, int rows, int columns,
                                          const NoiseCorrectedPvOptions& options) {
  CheckShapes(values, sigmas, rows, columns, options);
  if (options.basis != SmoothBasis::kLegendre || positions.size() != values.size()) {
    throw Error(ErrorCode::kBadInput, kNoiseCorrectedStage,
                std::to_string(positions.size()) + " positions for " + std::to_string(values.size()) +
                    " values (a Legendre basis needs one a value)");
  }
  Rows data =
      PositionedRows(values, sigmas, positions, rows, columns, Functions(options.basis, options.max_order));
  const RowBases bases(options.max_order, data.positions, data.present);
  return Solve(std::move(data), bases, options);
}

}  // namespace arcwheel::uncertainty
