#include "fitting/wheel_model.h"

#include <fmt/format.h>

#include <Eigen/Dense>
#include <algorithm>
#include <boost/math/distributions/chi_squared.hpp>
#include <cmath>
#include <map>
#include <numbers>

#include "core/error.h"
#include "core/interrupt.h"
#include "core/parallel.h"
#include "processing/uniform_cubic_bspline.h"

namespace arcwheel::fitting {
namespace {

constexpr const char* kStage = "fitting.model";
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

using Eigen::MatrixXd;
using Eigen::VectorXd;

// Ra(c), a(c), b(c): `knots` coefficients spread evenly over a turn, wrapping around.
struct PeriodicBasis {
  int knots = 0;
  void At(double phase_deg, int index[4], double weight[4]) const {
    const double t = phase_deg / 360.0 * knots;
    const double interval = std::floor(t);
    const processing::UniformCubicWeights cw = processing::UniformCubicBSplineWeights(t - interval);
    const int j = static_cast<int>(interval);
    for (int k = 0; k < 4; ++k) {
      index[k] = ((j - 1 + k) % knots + knots) % knots;
      weight[k] = cw.w[static_cast<std::size_t>(k)];
    }
  }
  // Row r of the returned matrix holds every coefficient's weight at phases_deg[r].
  [[nodiscard]] MatrixXd Matrix(std::span<const double> phases_deg) const {
    MatrixXd m = MatrixXd::Zero(static_cast<Eigen::Index>(phases_deg.size()), knots);
    for (std::size_t r = 0; r < phases_deg.size(); ++r) {
      int index[4];
      double weight[4];
      At(phases_deg[r], index, weight);
      for (int k = 0; k < 4; ++k) m(static_cast<Eigen::Index>(r), index[k]) += weight[k];
    }
    return m;
  }
};

// p(u): a cubic B-spline with uniform knots over [low_mm, low_mm + intervals * step_mm].
struct ProfileBasis {
  double low_mm = 0, step_mm = 1;
  int intervals = 1;
  [[nodiscard]] int size() const { return intervals + 3; }
  // First coefficient, weights and d(weight)/du at u (clamped to the span).
  int At(double u_mm, double weight[4], double slope[4]) const {
    const double t = std::clamp((u_mm - low_mm) / step_mm, 0.0, static_cast<double>(intervals));
    const int j = std::min(static_cast<int>(t), intervals - 1);
    const processing::UniformCubicWeights cw = processing::UniformCubicBSplineWeights(t - j);
    for (int k = 0; k < 4; ++k) {
      weight[k] = cw.w[static_cast<std::size_t>(k)];
      slope[k] = cw.dw[static_cast<std::size_t>(k)] / step_mm;
    }
    return j;
  }
};

// Knots per turn of Ra(c), a(c) and b(c).
struct Knots {
  int radius = 0, axial = 0, runout = 0;
  bool operator==(const Knots&) const = default;
};

// Where each function's coefficients sit in the parameter vector [Ra, a, b, p].
struct Layout {
  PeriodicBasis radius, axial, runout;
  ProfileBasis profile;
  [[nodiscard]] Knots knots() const { return {radius.knots, axial.knots, runout.knots}; }
  [[nodiscard]] int a0() const { return radius.knots; }
  [[nodiscard]] int b0() const { return radius.knots + axial.knots; }
  [[nodiscard]] int p0() const { return b0() + runout.knots; }
  [[nodiscard]] int size() const { return p0() + profile.size(); }
};

// The band's samples, read through the helix geometry on every pass (no copy of the scan).
struct Samples {
  std::span<const double> rho_mm;
  const processing::HelixGeometry& geometry;
  double band_low_mm, band_high_mm;
};

// J^T J, J^T r and r^T r of the samples at one set of coefficients (J: d(model)/d(coefficient)).
struct NormalEquations {
  MatrixXd jtj;
  VectorXd jtr;
  double rss = 0.0;
  std::size_t samples = 0;
  void Add(const NormalEquations& other) {
    jtj += other.jtj;
    jtr += other.jtr;
    rss += other.rss;
    samples += other.samples;
  }
};

// Evaluates the model at (c, y): the residual and the 16 non-zero entries of its Jacobian row.
// False where the sample lies beyond the arc (never for a sane band).
bool ModelRow(const Layout& layout, const VectorXd& theta, double phase_deg, double y_mm, double rho_mm,
              int column[16], double value[16], double& residual) {
  int ir[4], ia[4], ib[4];
  double wr[4], wa[4], wb[4], wp[4], sp[4];
  layout.radius.At(phase_deg, ir, wr);
  layout.axial.At(phase_deg, ia, wa);
  layout.runout.At(phase_deg, ib, wb);
  double ra = 0, a = 0, b = 0;
  for (int k = 0; k < 4; ++k) {
    ra += wr[k] * theta[ir[k]];
    a += wa[k] * theta[layout.a0() + ia[k]];
    b += wb[k] * theta[layout.b0() + ib[k]];
  }
  const double u = y_mm - a;
  const double s2 = ra * ra - u * u;
  if (!(s2 > 0.0)) return false;
  const double s = std::sqrt(s2);
  const int jp = layout.profile.At(u, wp, sp);
  double p = 0, dp = 0;
  for (int k = 0; k < 4; ++k) {
    p += wp[k] * theta[layout.p0() + jp + k];
    dp += sp[k] * theta[layout.p0() + jp + k];
  }
  residual = rho_mm - (b + s + p);
  const double d_ra = ra / s, d_a = u / s - dp;
  for (int k = 0; k < 4; ++k) {
    column[k] = ir[k];
    value[k] = d_ra * wr[k];
    column[4 + k] = layout.a0() + ia[k];
    value[4 + k] = d_a * wa[k];
    column[8 + k] = layout.b0() + ib[k];
    value[8 + k] = wb[k];
    column[12 + k] = layout.p0() + jp + k;
    value[12 + k] = wp[k];
  }
  return true;
}

double PhaseInTurn(double unwrapped_deg) {
  const double c = std::fmod(unwrapped_deg, 360.0);
  return c < 0.0 ? c + 360.0 : c;
}

// Neighbouring samples touch the same 16 coefficients (the phase crosses a knot every dozen
// samples or so, u a profile knot every few turns): their Jacobian rows are summed into a small
// fixed-size block, which is added into the normal equations only when the coefficients change.
class BlockAccumulator {
 public:
  explicit BlockAccumulator(NormalEquations& into) : into_(into) {}
  ~BlockAccumulator() { Flush(); }
  BlockAccumulator(const BlockAccumulator&) = delete;
  BlockAccumulator& operator=(const BlockAccumulator&) = delete;

  void Add(const int column[16], const double value[16], double residual) {
    if (!std::equal(column, column + 16, columns_)) {
      Flush();
      std::copy(column, column + 16, columns_);
    }
    const Eigen::Map<const Row> row(value);
    block_.selfadjointView<Eigen::Lower>().rankUpdate(row);
    rhs_.noalias() += residual * row;
    pending_ = true;
  }

  void Flush() {
    if (!pending_) return;
    const Block full = block_.selfadjointView<Eigen::Lower>();
    for (int r = 0; r < 16; ++r) {
      into_.jtr[columns_[r]] += rhs_[r];
      for (int c = 0; c < 16; ++c) into_.jtj(columns_[r], columns_[c]) += full(r, c);
    }
    block_.setZero();
    rhs_.setZero();
    pending_ = false;
  }

 private:
  using Block = Eigen::Matrix<double, 16, 16>;
  using Row = Eigen::Matrix<double, 16, 1>;
  NormalEquations& into_;
  int columns_[16] = {-1};
  Block block_ = Block::Zero();
  Row rhs_ = Row::Zero();
  bool pending_ = false;
};

// One pass over the band's samples on every core.
NormalEquations Accumulate(const Samples& samples, const Layout& layout, const VectorXd& theta) {
  const int n = layout.size();
  const int workers = WorkerCount(0);
  std::vector<NormalEquations> parts(static_cast<std::size_t>(workers));
  const std::size_t total = samples.rho_mm.size();
  RunOnWorkers(workers, [&](int worker) {
    NormalEquations& part = parts[static_cast<std::size_t>(worker)];
    part.jtj = MatrixXd::Zero(n, n);
    part.jtr = VectorXd::Zero(n);
    const std::size_t begin = total * static_cast<std::size_t>(worker) / static_cast<std::size_t>(workers);
    const std::size_t end = total * static_cast<std::size_t>(worker + 1) / static_cast<std::size_t>(workers);
    BlockAccumulator block(part);
    int column[16];
    double value[16];
    double residual = 0;
    for (std::size_t i = begin; i < end; ++i) {
      const double rho = samples.rho_mm[i];
      if (!std::isfinite(rho)) continue;
      const double y = samples.geometry.AxialAt(i);
      if (y < samples.band_low_mm || y > samples.band_high_mm) continue;
      if (!ModelRow(layout, theta, PhaseInTurn(samples.geometry.PhaseAt(i)), y, rho, column, value,
                    residual)) {
        continue;
      }
      block.Add(column, value, residual);
      part.rss += residual * residual;
      ++part.samples;
    }
  });
  NormalEquations sum = std::move(parts[0]);
  for (std::size_t w = 1; w < parts.size(); ++w) sum.Add(parts[w]);
  return sum;
}

// The constraints on p: its integrals against 1, u and u^2 over the band vanish. Returns an
// orthonormal basis of the coefficient vectors that meet them (size x (size - 3)).
MatrixXd ProfileNullSpace(const ProfileBasis& basis, double half_width_mm) {
  MatrixXd constraints = MatrixXd::Zero(3, basis.size());
  // Composite 4-point Gauss-Legendre: exact for the piecewise-cubic integrands times u^2 on each
  // subinterval that no knot crosses, and 1e-12 close where one does.
  constexpr double kNodes[4] = {-0.8611363115940526, -0.3399810435848563, 0.3399810435848563,
                                0.8611363115940526};
  constexpr double kWeights[4] = {0.3478548451374538, 0.6521451548625461, 0.6521451548625461,
                                  0.3478548451374538};
  const int pieces = 2048;
  const double h = 2.0 * half_width_mm / pieces;
  for (int piece = 0; piece < pieces; ++piece) {
    const double mid = -half_width_mm + (piece + 0.5) * h;
    for (int q = 0; q < 4; ++q) {
      const double u = mid + 0.5 * h * kNodes[q];
      double w[4], slope[4];
      const int first = basis.At(u, w, slope);
      for (int k = 0; k < 4; ++k) {
        const double m = 0.5 * h * kWeights[q] * w[k];
        constraints(0, first + k) += m;
        constraints(1, first + k) += m * u;
        constraints(2, first + k) += m * u * u;
      }
    }
  }
  Eigen::JacobiSVD<MatrixXd> svd(constraints, Eigen::ComputeFullV);
  return svd.matrixV().rightCols(basis.size() - 3);
}

// The matrix that writes a periodic spline of `coarse` knots in the basis of `fine` knots (exact:
// the coarse knots are a subset of the fine ones).
MatrixXd Refinement(int fine, int coarse) {
  // The choice of knots asks for the same few matrices again and again.
  thread_local std::map<std::pair<int, int>, MatrixXd> known;
  if (const auto it = known.find({fine, coarse}); it != known.end()) return it->second;
  std::vector<double> phases;
  for (int i = 0; i < 8 * fine; ++i) phases.push_back((i + 0.37) * 360.0 / (8.0 * fine));
  const MatrixXd fine_basis = PeriodicBasis{fine}.Matrix(phases);
  const MatrixXd coarse_basis = PeriodicBasis{coarse}.Matrix(phases);
  return known[{fine, coarse}] = fine_basis.colPivHouseholderQr().solve(coarse_basis);
}

// Maps reduced parameters [Ra, a, b (coarse knots), p in the constraints' null space] to the full
// parameters of `fine`.
MatrixXd Reduction(const Layout& fine, const Knots& coarse, const MatrixXd& null_space) {
  const MatrixXd radius = Refinement(fine.radius.knots, coarse.radius);
  const MatrixXd axial = Refinement(fine.axial.knots, coarse.axial);
  const MatrixXd runout = Refinement(fine.runout.knots, coarse.runout);
  const Eigen::Index a0 = coarse.radius, b0 = a0 + coarse.axial, p0 = b0 + coarse.runout;
  MatrixXd t = MatrixXd::Zero(fine.size(), p0 + null_space.cols());
  t.block(0, 0, radius.rows(), radius.cols()) = radius;
  t.block(fine.a0(), a0, axial.rows(), axial.cols()) = axial;
  t.block(fine.b0(), b0, runout.rows(), runout.cols()) = runout;
  t.block(fine.p0(), p0, null_space.rows(), null_space.cols()) = null_space;
  return t;
}

struct Solution {
  VectorXd theta;          // full parameters
  MatrixXd reduction;      // full = reduction * reduced
  MatrixXd reduced_jtj;    // at the solution
  NormalEquations normal;  // at the solution
  int iterations = 0;
};

// Gauss-Newton on the reduced parameters, halving a step that raises the residual.
Solution GaussNewton(const Samples& samples, const Layout& layout, const MatrixXd& reduction, VectorXd theta,
                     int max_iterations) {
  Solution solution;
  solution.reduction = reduction;
  VectorXd previous = theta;
  double previous_rss = std::numeric_limits<double>::infinity();
  for (int iteration = 1; iteration <= max_iterations; ++iteration) {
    ThrowIfInterrupted();
    NormalEquations normal = Accumulate(samples, layout, theta);
    if (normal.rss > previous_rss * (1.0 + 1e-12) && (theta - previous).cwiseAbs().maxCoeff() > 1e-13) {
      theta = previous + 0.5 * (theta - previous);  // the step overshot: take half of it
      continue;
    }
    const MatrixXd reduced_jtj = reduction.transpose() * normal.jtj * reduction;
    const VectorXd step = reduction * reduced_jtj.ldlt().solve(reduction.transpose() * normal.jtr);
    solution = {theta, reduction, reduced_jtj, std::move(normal), iteration};
    if (!step.allFinite()) break;
    previous = theta;
    previous_rss = solution.normal.rss;
    theta += step;
    // Converged when the step would lower the residual sum of squares by a negligible fraction
    // (the linearised decrease is step . J^T r), or moves no coefficient by more than 1e-11 mm.
    const double decrease = step.dot(solution.normal.jtr);
    if (decrease <= 1e-10 * solution.normal.rss || step.cwiseAbs().maxCoeff() < 1e-11) {
      solution.theta = theta;
      return solution;
    }
  }
  throw Error(ErrorCode::kFitFailed, kStage,
              fmt::format("the wheel model did not converge in {} Gauss-Newton iterations", max_iterations));
}

// The fine fit's normal equations linearised at its solution, restricted to coarser knots
// (theta = T x): the x minimising RSS = |z - J T x|^2 with z = r + J theta, that RSS, and T^T J^T J T.
struct LinearisedFit {
  VectorXd x;
  double rss = 0.0;
  MatrixXd reduced_jtj;
};

LinearisedFit Linearise(const Solution& fine, const MatrixXd& reduction) {
  const MatrixXd& jtj = fine.normal.jtj;
  const VectorXd jtz = fine.normal.jtr + jtj * fine.theta;
  const double ztz =
      fine.normal.rss + 2.0 * fine.theta.dot(fine.normal.jtr) + fine.theta.dot(jtj * fine.theta);
  const VectorXd rhs = reduction.transpose() * jtz;
  LinearisedFit fit;
  fit.reduced_jtj = reduction.transpose() * jtj * reduction;
  fit.x = fit.reduced_jtj.ldlt().solve(rhs);
  fit.rss = std::max(ztz - rhs.dot(fit.x), 0.0);
  return fit;
}

// The knot counts to choose from: the one given, else kKnotChoices, and for Ra and a also a
// single knot (a constant function), so that a wheel without variation is modelled as such.
std::vector<int> KnotCandidates(int fixed, bool constant_allowed) {
  if (fixed > 0) return {fixed};
  std::vector<int> choices(std::begin(kKnotChoices), std::end(kKnotChoices));
  if (constant_allowed) choices.insert(choices.begin(), 1);
  return choices;
}

// Value and 1-sigma of w^T theta.
std::pair<double, double> Linear(const VectorXd& w, const VectorXd& theta, const MatrixXd& covariance) {
  return {w.dot(theta), std::sqrt(std::max(w.dot(covariance * w), 0.0))};
}

// The Wald test of "Ra(c) is constant": chi-square of the coefficients' deviations from their mean
// against their covariance, with knots - 1 degrees of freedom.
struct Variation {
  double chi2 = 0, p_value = 1;
  int dof = 0;
};

Variation WaldTestOfConstancy(const VectorXd& r, const MatrixXd& c) {
  const Eigen::Index k = r.size();
  const MatrixXd centre = MatrixXd::Identity(k, k) - MatrixXd::Constant(k, k, 1.0 / static_cast<double>(k));
  const VectorXd deviation = centre * r;
  Eigen::SelfAdjointEigenSolver<MatrixXd> eigen(centre * c * centre);
  Variation v;
  for (Eigen::Index i = 1; i < k; ++i) {  // eigenvalue 0 (the constant direction) comes first
    const double projection = eigen.eigenvectors().col(i).dot(deviation);
    const double variance = eigen.eigenvalues()[i];
    // Noise-free data leave no variance: any deviation is then infinitely significant.
    v.chi2 += variance > 0.0 ? projection * projection / variance
                             : (projection != 0.0 ? std::numeric_limits<double>::infinity() : 0.0);
  }
  v.dof = static_cast<int>(k - 1);
  v.p_value = std::isfinite(v.chi2)
                  ? boost::math::cdf(boost::math::complement(boost::math::chi_squared(v.dof), v.chi2))
                  : 0.0;
  return v;
}

// The test at the chosen knots of Ra, or at 4 when the information criterion chose a constant
// (a test needs an alternative), from the fine fit's linearised normal equations.
Variation VariationAtFineFit(const Solution& fine, const Layout& fine_layout, Knots knots,
                             const MatrixXd& null_space) {
  knots.radius = std::max(knots.radius, 4);
  const MatrixXd t = Reduction(fine_layout, knots, null_space);
  const double n = static_cast<double>(fine.normal.samples);
  const LinearisedFit linear = Linearise(fine, t);
  const double sigma2 = linear.rss / (n - static_cast<double>(t.cols()));
  const MatrixXd covariance = sigma2 * linear.reduced_jtj.inverse();
  return WaldTestOfConstancy(linear.x.head(knots.radius),
                             covariance.topLeftCorner(knots.radius, knots.radius));
}

struct Fitted {
  Layout layout;
  Variation variation;
  Solution solution;
  MatrixXd covariance;  // of the full parameters
  double sigma2 = 0;
};

void SampleFunctions(const Fitted& f, std::span<const double> phases_deg, WheelModel& model) {
  const Layout& l = f.layout;
  const MatrixXd radius = l.radius.Matrix(phases_deg);
  const MatrixXd axial = l.axial.Matrix(phases_deg);
  const MatrixXd runout = l.runout.Matrix(phases_deg);
  for (Eigen::Index r = 0; r < radius.rows(); ++r) {
    VectorXd w = VectorXd::Zero(l.size());
    w.head(l.radius.knots) = radius.row(r).transpose();
    auto [ra, ra_sigma] = Linear(w, f.solution.theta, f.covariance);
    w.setZero();
    w.segment(l.a0(), l.axial.knots) = axial.row(r).transpose();
    auto [a, a_sigma] = Linear(w, f.solution.theta, f.covariance);
    w.setZero();
    w.segment(l.b0(), l.runout.knots) = runout.row(r).transpose();
    auto [b, b_sigma] = Linear(w, f.solution.theta, f.covariance);
    model.arc_radius_mm.push_back(ra);
    model.arc_radius_sigma_mm.push_back(ra_sigma);
    model.center_axial_mm.push_back(a);
    model.center_axial_sigma_mm.push_back(a_sigma);
    model.center_radial_mm.push_back(b);
    model.center_radial_sigma_mm.push_back(b_sigma);
  }
}

void SummariseRadius(const Fitted& f, std::span<const double> phases_deg, WheelModel& model) {
  const Layout& l = f.layout;
  const Eigen::Index k = l.radius.knots;
  const VectorXd r = f.solution.theta.head(k);
  const MatrixXd c = f.covariance.topLeftCorner(k, k);
  // Every periodic basis function has the same integral, so the mean over a turn is the mean
  // coefficient.
  const VectorXd mean = VectorXd::Constant(k, 1.0 / static_cast<double>(k));
  model.mean_arc_radius_mm = mean.dot(r);
  model.mean_arc_radius_sigma_mm = std::sqrt(mean.dot(c * mean));
  const MatrixXd at = l.radius.Matrix(phases_deg);
  const VectorXd values = at * r;
  Eigen::Index high = 0, low = 0;
  values.maxCoeff(&high);
  values.minCoeff(&low);
  if (k == 1) return;  // a constant radius: no range
  const VectorXd range = (at.row(high) - at.row(low)).transpose();
  model.arc_radius_range_mm = range.dot(r);
  model.arc_radius_range_sigma_mm = std::sqrt(std::max(range.dot(c * range), 0.0));
}

void RadiusHarmonics(const Fitted& f, int harmonics, WheelModel& model) {
  const Layout& l = f.layout;
  const Eigen::Index k = l.radius.knots;
  const int points = 64 * l.radius.knots;
  std::vector<double> phases(static_cast<std::size_t>(points));
  for (int i = 0; i < points; ++i) phases[static_cast<std::size_t>(i)] = i * 360.0 / points;
  const MatrixXd at = l.radius.Matrix(phases);
  const VectorXd r = f.solution.theta.head(k);
  const MatrixXd c = f.covariance.topLeftCorner(k, k);
  const int orders = l.radius.knots < 4 ? 0 : std::min(harmonics, std::max(1, l.radius.knots / 2 - 1));
  for (int order = 1; order <= orders; ++order) {
    // Ra's Fourier coefficients: A cos(order c) + B sin(order c), linear in the coefficients.
    VectorXd cos_w = VectorXd::Zero(k), sin_w = VectorXd::Zero(k);
    for (int i = 0; i < points; ++i) {
      const double angle = order * phases[static_cast<std::size_t>(i)] * std::numbers::pi / 180.0;
      cos_w += 2.0 / points * std::cos(angle) * at.row(i).transpose();
      sin_w += 2.0 / points * std::sin(angle) * at.row(i).transpose();
    }
    const double a = cos_w.dot(r), b = sin_w.dot(r);
    const double va = cos_w.dot(c * cos_w), vb = sin_w.dot(c * sin_w), cab = cos_w.dot(c * sin_w);
    const double amplitude = std::hypot(a, b);
    RadiusHarmonic h;
    h.order = order;
    h.amplitude_um = amplitude * 1e3;
    // amplitude cos(order c + phase) = A cos + B sin with A = amp cos(phase), B = -amp sin(phase).
    h.phase_deg = std::atan2(-b, a) * 180.0 / std::numbers::pi;
    if (amplitude > 0) {
      h.amplitude_sigma_um =
          std::sqrt(std::max(a * a * va + b * b * vb + 2 * a * b * cab, 0.0)) / amplitude * 1e3;
      h.phase_sigma_deg = std::sqrt(std::max(b * b * va + a * a * vb - 2 * a * b * cab, 0.0)) /
                          (amplitude * amplitude) * 180.0 / std::numbers::pi;
    }
    model.radius_harmonics.push_back(h);
  }
}

void SampleProfile(const Fitted& f, double half_width_mm, WheelModel& model) {
  const Layout& l = f.layout;
  const int steps = static_cast<int>(std::ceil(2.0 * half_width_mm / 0.1));
  double low = std::numeric_limits<double>::infinity(), high = -low;
  for (int i = 0; i <= steps; ++i) {
    const double u = -half_width_mm + 2.0 * half_width_mm * i / steps;
    double w[4], slope[4];
    const int first = l.profile.At(u, w, slope);
    VectorXd row = VectorXd::Zero(l.size());
    for (int k = 0; k < 4; ++k) row[l.p0() + first + k] = w[k];
    const auto [p, sigma] = Linear(row, f.solution.theta, f.covariance);
    model.profile_u_mm.push_back(u);
    model.profile_error_um.push_back(p * 1e3);
    model.profile_error_sigma_um.push_back(sigma * 1e3);
    low = std::min(low, p);
    high = std::max(high, p);
  }
  model.profile_pv_um = (high - low) * 1e3;
}

// Mean residual of the final fit per cell of the map's grid.
std::vector<double> ResidualMap(const Samples& samples, const Fitted& f, const processing::WheelMap& map) {
  const std::size_t n_phase = map.n_phase(), n_y = map.n_y();
  std::vector<double> sum(n_phase * n_y, 0.0);
  std::vector<int> count(n_phase * n_y, 0);
  if (n_phase == 0 || n_y < 2) return {};
  const double phase_step = 360.0 / static_cast<double>(n_phase);
  const double y0 = map.y_mm.front(), y_step = map.y_mm[1] - map.y_mm[0];
  int column[16];
  double value[16];
  double residual = 0;
  for (std::size_t i = 0; i < samples.rho_mm.size(); ++i) {
    const double rho = samples.rho_mm[i];
    if (!std::isfinite(rho)) continue;
    const double y = samples.geometry.AxialAt(i);
    if (y < samples.band_low_mm || y > samples.band_high_mm) continue;
    const double c = PhaseInTurn(samples.geometry.PhaseAt(i));
    if (!ModelRow(f.layout, f.solution.theta, c, y, rho, column, value, residual)) continue;
    const auto p = static_cast<std::size_t>(std::lround(c / phase_step)) % n_phase;
    const long a = std::lround((y - y0) / y_step);
    if (a < 0 || a >= static_cast<long>(n_y)) continue;
    sum[p * n_y + static_cast<std::size_t>(a)] += residual;
    ++count[p * n_y + static_cast<std::size_t>(a)];
  }
  for (std::size_t cell = 0; cell < sum.size(); ++cell) {
    sum[cell] = count[cell] > 0 ? sum[cell] / count[cell] * 1e3 : kNaN;
  }
  return sum;
}

Layout MakeLayout(const Knots& knots, double half_width_mm, double knot_step_mm) {
  // p spans the band and a margin for the wobble of a(c) about its mean (u beyond it is clamped):
  // a wider margin would leave the outer coefficients without data.
  const double margin = 0.02;
  const int intervals =
      std::max(1, static_cast<int>(std::ceil(2.0 * (half_width_mm + margin) / knot_step_mm)));
  const double step = 2.0 * (half_width_mm + margin) / intervals;
  return {PeriodicBasis{knots.radius}, PeriodicBasis{knots.axial}, PeriodicBasis{knots.runout},
          ProfileBasis{-(half_width_mm + margin), step, intervals}};
}

VectorXd StartingPoint(const Layout& layout, const WheelFit& fit) {
  VectorXd theta = VectorXd::Zero(layout.size());
  theta.head(layout.radius.knots).setConstant(fit.mean_arc_radius_mm);
  theta.segment(layout.a0(), layout.axial.knots).setConstant(fit.mean_center_axial_mm);
  theta.segment(layout.b0(), layout.runout.knots).setConstant(fit.mean_center_radial_mm);
  return theta;
}

// The BIC of coarser knots, from the fine fit's normal equations linearised at its solution.
double Bic(const Solution& fine, const Layout& fine_layout, const Knots& knots, const MatrixXd& null_space) {
  const MatrixXd t = Reduction(fine_layout, knots, null_space);
  const double n = static_cast<double>(fine.normal.samples);
  return n * std::log(Linearise(fine, t).rss / n) + static_cast<double>(t.cols()) * std::log(n);
}

// Each function's knots in turn (Ra, then a, then b, twice over), the one with the least BIC
// while the others stay: a few dozen small dense solves instead of every combination. Ra comes
// first, while b is still at its finest: Ra and b are nearly interchangeable on a short arc, and a
// b chosen first too coarse would leave its misfit for Ra to take up.
Knots ChooseKnots(const Solution& fine, const Layout& fine_layout, const std::vector<int> choices[3],
                  const MatrixXd& null_space) {
  Knots best = fine_layout.knots();
  int Knots::*const members[3] = {&Knots::radius, &Knots::axial, &Knots::runout};
  for (int round = 0; round < 2; ++round) {
    for (int f = 0; f < 3; ++f) {
      double least = std::numeric_limits<double>::infinity();
      int chosen = best.*members[f];
      for (const int k : choices[f]) {
        Knots trial = best;
        trial.*members[f] = k;
        const double bic = Bic(fine, fine_layout, trial, null_space);
        if (bic < least) {
          least = bic;
          chosen = k;
        }
      }
      best.*members[f] = chosen;
    }
  }
  return best;
}

// Fits at the finest knots asked for, then, where the knots are to be chosen, picks them by the
// BIC from the fine fit's linearised normal equations and refits there.
Fitted FitAndChoose(const Samples& samples, const WheelFit& fit, const WheelModelOptions& options,
                    double half_width_mm, WheelModel& model) {
  const std::vector<int> choices[3] = {KnotCandidates(options.radius_knots, true),
                                       KnotCandidates(options.axial_knots, true),
                                       KnotCandidates(options.runout_knots, false)};
  const Layout fine = MakeLayout({choices[0].back(), choices[1].back(), choices[2].back()}, half_width_mm,
                                 options.profile_knot_step_mm);
  const MatrixXd null_space = ProfileNullSpace(fine.profile, half_width_mm);
  Solution best = GaussNewton(samples, fine, Reduction(fine, fine.knots(), null_space),
                              StartingPoint(fine, fit), options.max_iterations);
  model.knots_chosen = choices[0].size() > 1 || choices[1].size() > 1 || choices[2].size() > 1;
  const Knots knots = model.knots_chosen ? ChooseKnots(best, fine, choices, null_space) : fine.knots();
  Fitted fitted;
  fitted.layout = MakeLayout(knots, half_width_mm, options.profile_knot_step_mm);
  fitted.variation = VariationAtFineFit(best, fine, knots, null_space);
  if (!(knots == fine.knots())) {
    const VectorXd start_reduced = Linearise(best, Reduction(fine, knots, null_space)).x;
    const MatrixXd reduction = Reduction(fitted.layout, knots, null_space);
    const int iterations = best.iterations;
    best = GaussNewton(samples, fitted.layout, reduction, reduction * start_reduced, options.max_iterations);
    best.iterations += iterations;
  }
  fitted.solution = std::move(best);
  return fitted;
}

}  // namespace

std::vector<std::string> WheelModelOptions::Problems() const {
  std::vector<std::string> problems;
  const auto knots = [&](const char* name, int value) {
    if (value != 0 && value != 1 && (value < 4 || value > 360)) {
      problems.push_back(fmt::format("{} = {} violates 0 (chosen from the data), 1 or 4..360", name, value));
    }
  };
  knots("model-knots", radius_knots);
  knots("model-axial-knots", axial_knots);
  knots("model-runout-knots", runout_knots);
  if (!(profile_knot_step_mm >= 0.05 && profile_knot_step_mm <= 10.0)) {
    problems.push_back(fmt::format("model-profile-step-mm = {} violates 0.05..10", profile_knot_step_mm));
  }
  if (max_iterations < 1)
    problems.push_back(fmt::format("model max_iterations = {} violates >= 1", max_iterations));
  if (!(significance_level > 0.0 && significance_level < 0.5)) {
    problems.push_back(
        fmt::format("model significance_level = {} violates 0 < level < 0.5", significance_level));
  }
  if (harmonics < 1) problems.push_back(fmt::format("model harmonics = {} violates >= 1", harmonics));
  return problems;
}

WheelModel FitWheelModel(std::span<const double> rho_mm, const processing::HelixGeometry& geometry,
                         const processing::WheelMap& map, const WheelFit& fit,
                         const WheelModelOptions& options) {
  ThrowIfProblems(ErrorCode::kInvalidOption, kStage, options.Problems());
  WheelModel model;
  model.band_low_mm = fit.band_low_mm;
  model.band_high_mm = fit.band_high_mm;
  model.center_axial_reference_mm = fit.mean_center_axial_mm;
  const double half_width_mm =
      std::max(fit.mean_center_axial_mm - fit.band_low_mm, fit.band_high_mm - fit.mean_center_axial_mm);
  const Samples samples{rho_mm, geometry, fit.band_low_mm, fit.band_high_mm};

  Fitted f = FitAndChoose(samples, fit, options, half_width_mm, model);
  const Solution& s = f.solution;
  const auto parameters = static_cast<std::size_t>(s.reduction.cols());
  if (s.normal.samples < 4 * parameters) {
    throw Error(ErrorCode::kFitFailed, kStage,
                fmt::format("the band holds {} samples, too few for the wheel model's {} parameters",
                            s.normal.samples, parameters));
  }
  f.sigma2 = s.normal.rss / static_cast<double>(s.normal.samples - parameters);
  f.covariance = s.reduction * (f.sigma2 * s.reduced_jtj.inverse()) * s.reduction.transpose();

  model.fitted = true;
  model.radius_knots = f.layout.radius.knots;
  model.axial_knots = f.layout.axial.knots;
  model.runout_knots = f.layout.runout.knots;
  model.variation_chi2 = f.variation.chi2;
  model.variation_dof = f.variation.dof;
  model.variation_p_value = f.variation.p_value;
  model.profile_coefficients = f.layout.profile.size();
  model.samples = s.normal.samples;
  model.parameters = static_cast<int>(parameters);
  model.iterations = s.iterations;
  model.residual_rms_um = std::sqrt(s.normal.rss / static_cast<double>(s.normal.samples)) * 1e3;
  model.noise_sigma_um = map.noise_sigma_mm * 1e3;
  model.phase_deg = map.phase_deg;
  SampleFunctions(f, map.phase_deg, model);
  SummariseRadius(f, map.phase_deg, model);
  model.significance_level = options.significance_level;
  model.variation_significant = model.variation_p_value < options.significance_level;
  RadiusHarmonics(f, options.harmonics, model);
  SampleProfile(f, half_width_mm, model);
  model.residual_um = ResidualMap(samples, f, map);
  model.coefficients.assign(s.theta.data(), s.theta.data() + s.theta.size());
  model.covariance.assign(f.covariance.data(), f.covariance.data() + f.covariance.size());
  return model;
}

WheelModel FitWheelModel(std::span<const float> rho_mm, const processing::HelixGeometry& geometry,
                         const processing::WheelMap& map, const WheelFit& fit,
                         const WheelModelOptions& options) {
  const std::vector<double> widened(rho_mm.begin(), rho_mm.end());
  return FitWheelModel(std::span<const double>(widened), geometry, map, fit, options);
}

}  // namespace arcwheel::fitting
