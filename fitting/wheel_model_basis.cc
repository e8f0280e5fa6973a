// The wheel model's layouts and changes of basis: the profile's constraints and the matrices that
// write coarser knots in the basis of finer ones.
#include "fitting/wheel_model_basis.h"

#include <map>
#include <utility>
#include <vector>

#include "core/dense.h"

namespace arcwheel::fitting::internal {

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
  const MatrixXd v = dense::JacobiSvd(constraints, Eigen::ComputeFullV).v;
  return v.rightCols(basis.size() - 3);
}

namespace {

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
  // The exact matrix is banded (a coarse function spans few fine ones), its entries 1 / ratio^3
  // (2.4e-4 for 4 knots in 64) or more; the solve leaves up to 1e-15 elsewhere, which would fill
  // the whole block for Project's products.
  MatrixXd refinement = dense::ColPivQrSolve(fine_basis, coarse_basis);
  refinement = refinement.unaryExpr([](double v) { return std::abs(v) < 1e-12 ? 0.0 : v; });
  return known[{fine, coarse}] = refinement;
}

}  // namespace

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

}  // namespace arcwheel::fitting::internal
