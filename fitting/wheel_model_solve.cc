// The wheel model's solve: Gauss-Newton on the reduced parameters, one step from a warm start,
// and the fine fit's normal equations linearised at coarser knots.
#include <fmt/format.h>

#include <Eigen/Dense>
#include <Eigen/Sparse>
#include <cstddef>
#include <limits>
#include <utility>
#include <vector>

#include "core/dense.h"
#include "core/error.h"
#include "core/interrupt.h"
#include "fitting/wheel_model_impl.h"

namespace arcwheel::fitting::internal {
namespace {

// T^T H T for a reduction T (mostly zeros: block-diagonal, and sparse within its blocks).
// Each column's non-zero entries are listed once, and the products run over them: H T as sums of
// H's columns (contiguous, vectorised), T^T (H T) as short sums per entry of its lower triangle.
// Eigen's sparse products cost ten times as much on these few-hundred-row matrices.
MatrixXd Project(const MatrixXd& h, const MatrixXd& t) {
  const Eigen::Index n = t.rows(), m = t.cols();
  std::vector<Eigen::Index> start = {0}, row;  // column j's entries: start[j] .. start[j + 1]
  std::vector<double> value;
  for (Eigen::Index j = 0; j < m; ++j) {
    for (Eigen::Index i = 0; i < n; ++i) {
      if (t(i, j) == 0.0) continue;
      row.push_back(i);
      value.push_back(t(i, j));
    }
    start.push_back(static_cast<Eigen::Index>(row.size()));
  }
  const auto entries = [&](Eigen::Index j) {
    return std::pair<std::size_t, std::size_t>(start[static_cast<std::size_t>(j)],
                                               start[static_cast<std::size_t>(j) + 1]);
  };
  MatrixXd ht = MatrixXd::Zero(n, m);
  for (Eigen::Index j = 0; j < m; ++j) {
    const auto [from, to] = entries(j);
    for (std::size_t e = from; e < to; ++e) ht.col(j).noalias() += value[e] * h.col(row[e]);
  }
  MatrixXd result(m, m);
  for (Eigen::Index i = 0; i < m; ++i) {
    const auto [from, to] = entries(i);
    for (Eigen::Index j = 0; j <= i; ++j) {
      double sum = 0.0;
      for (std::size_t e = from; e < to; ++e) sum += value[e] * ht(row[e], j);
      result(i, j) = sum;
      result(j, i) = sum;
    }
  }
  return result;
}

// H^-1 b for a normal matrix: by Cholesky, or by LDL^T where rounding leaves H not quite
// positive definite.
VectorXd SolveNormal(const MatrixXd& h, const VectorXd& b) { return dense::SemidefiniteSolve(h, b); }

}  // namespace

// Gauss-Newton on the reduced parameters, halving a step that raises the residual. Converged when
// the step would lower the residual sum of squares by a negligible fraction (the linearised
// decrease is step . J^T r), or moves no coefficient by more than 1e-11 mm.
template <typename Sample>
Solution Converge(const Samples<Sample>& samples, const Layout& layout, const MatrixXd& reduction,
                  VectorXd theta, ConvergeRequest request) {
  Solution solution;
  solution.reduction = reduction;
  VectorXd previous = theta;
  double previous_rss = std::numeric_limits<double>::infinity();
  MatrixXd chord_jtj = std::move(request.reduced_jtj);
  for (int iteration = 1; iteration <= request.max_iterations; ++iteration) {
    ThrowIfInterrupted();
    const bool chord = chord_jtj.size() != 0;
    PassResult pass =
        Accumulate(samples, layout, theta,
                   {.stride = request.stride, .normal_matrix = !chord, .grid = request.grid}, request.ranges);
    NormalEquations& normal = pass.normal;
    if (normal.rss > previous_rss * (1.0 + 1e-12) && (theta - previous).cwiseAbs().maxCoeff() > 1e-13) {
      theta = previous + 0.5 * (theta - previous);  // the step overshot: take half of it
      chord_jtj.resize(0, 0);
      continue;
    }
    MatrixXd reduced_jtj = chord ? chord_jtj : Project(normal.jtj, reduction);
    chord_jtj.resize(0, 0);  // a chord step once only
    const VectorXd step = reduction * SolveNormal(reduced_jtj, reduction.transpose() * normal.jtr);
    solution.at = theta;
    solution.theta = theta;
    solution.reduced_jtj = std::move(reduced_jtj);
    solution.normal = std::move(normal);
    solution.cells = std::move(pass.cells);
    solution.ranges = pass.ranges;
    solution.iterations = iteration;
    if (!step.allFinite()) break;
    previous = theta;
    previous_rss = solution.normal.rss;
    theta += step;
    const double decrease = step.dot(solution.normal.jtr);
    if (decrease <= 1e-10 * solution.normal.rss || step.cwiseAbs().maxCoeff() < 1e-11) {
      solution.theta = theta;
      solution.converged = true;
      return solution;
    }
  }
  if (request.throw_if_not_converged) {
    throw Error(ErrorCode::kFitFailed, kStage,
                fmt::format("the wheel model did not converge in {} Gauss-Newton iterations",
                            request.max_iterations));
  }
  return solution;
}

// One Gauss-Newton step over every sample from theta, without the test for convergence: the fine
// fit whose normal equations choose the knots, at a start close enough for its linearisation.
template <typename Sample>
Solution OneStep(const Samples<Sample>& samples, const Layout& layout, const MatrixXd& reduction,
                 const VectorXd& theta) {
  PassResult pass = Accumulate(samples, layout, theta, {});
  Solution solution;
  solution.reduction = reduction;
  solution.at = theta;
  solution.reduced_jtj = Project(pass.normal.jtj, reduction);
  solution.theta =
      theta + reduction * SolveNormal(solution.reduced_jtj, reduction.transpose() * pass.normal.jtr);
  solution.normal = std::move(pass.normal);
  solution.ranges = pass.ranges;
  solution.iterations = 1;
  return solution;
}

LinearisedFit Linearise(const Solution& fine, const MatrixXd& reduction) {
  const MatrixXd& jtj = fine.normal.jtj;
  const Eigen::SparseMatrix<double> t = reduction.sparseView();
  const Eigen::SparseMatrix<double> tt = t.transpose() * t;  // block-diagonal
  const VectorXd x0 = Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>>(tt).solve(t.transpose() * fine.at);
  const VectorXd g = fine.at - reduction * x0;
  const VectorXd jtj_g = jtj * g;
  const VectorXd jtz = fine.normal.jtr + jtj_g;
  const double ztz = fine.normal.rss + 2.0 * g.dot(fine.normal.jtr) + g.dot(jtj_g);
  const VectorXd rhs = reduction.transpose() * jtz;
  LinearisedFit fit;
  fit.reduced_jtj = Project(jtj, reduction);
  const VectorXd correction = SolveNormal(fit.reduced_jtj, rhs);
  fit.x = x0 + correction;
  fit.rss = std::max(ztz - rhs.dot(correction), 0.0);
  return fit;
}

template Solution Converge(const Samples<double>& samples, const Layout& layout, const MatrixXd& reduction,
                           VectorXd theta, ConvergeRequest request);
template Solution Converge(const Samples<float>& samples, const Layout& layout, const MatrixXd& reduction,
                           VectorXd theta, ConvergeRequest request);
template Solution OneStep(const Samples<double>& samples, const Layout& layout, const MatrixXd& reduction,
                          const VectorXd& theta);
template Solution OneStep(const Samples<float>& samples, const Layout& layout, const MatrixXd& reduction,
                          const VectorXd& theta);

}  // namespace arcwheel::fitting::internal
