// The wheel model's choice of knots by the BIC, and the Wald test of Ra's constancy, both from the
// fine fit's normal equations linearised at coarser knots.
#include <algorithm>
#include <array>
#include <cmath>
#include <iterator>
#include <limits>
#include <map>
#include <vector>

#include "core/dense.h"
#include "core/statistics.h"
#include "fitting/wheel_model_impl.h"

namespace arcwheel::fitting::internal {

// The knot counts to choose from: the one given, else kKnotChoices, and for Ra and a also a
// single knot (a constant function), so that a wheel without variation is modelled as such.
std::vector<int> KnotCandidates(int fixed, bool constant_allowed) {
  if (fixed > 0) return {fixed};
  std::vector<int> choices(std::begin(kKnotChoices), std::end(kKnotChoices));
  if (constant_allowed) choices.insert(choices.begin(), 1);
  return choices;
}

namespace {

// The test itself (Variation).
Variation WaldTestOfConstancy(const VectorXd& r, const MatrixXd& c) {
  const Eigen::Index k = r.size();
  const MatrixXd centre = MatrixXd::Identity(k, k) - MatrixXd::Constant(k, k, 1.0 / static_cast<double>(k));
  const VectorXd deviation = centre * r;
  const dense::SymmetricEigen eigen = dense::SymmetricEigenDecomposition(centre * c * centre);
  Variation v;
  for (Eigen::Index i = 1; i < k; ++i) {  // eigenvalue 0 (the constant direction) comes first
    const double projection = eigen.vectors.col(i).dot(deviation);
    const double variance = eigen.values[i];
    // Noise-free data leave no variance: any deviation is then infinitely significant.
    v.chi2 += variance > 0.0 ? projection * projection / variance
                             : (projection != 0.0 ? std::numeric_limits<double>::infinity() : 0.0);
  }
  v.dof = static_cast<int>(k - 1);
  v.p_value = std::isfinite(v.chi2) ? ChiSquaredUpperTail(v.chi2, v.dof) : 0.0;
  return v;
}

}  // namespace

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

namespace {

// The BIC of coarser knots, from the fine fit's normal equations linearised at its solution.
double Bic(const Solution& fine, const Layout& fine_layout, const Knots& knots, const MatrixXd& null_space) {
  const MatrixXd t = Reduction(fine_layout, knots, null_space);
  const double n = static_cast<double>(fine.normal.samples);
  return n * std::log(Linearise(fine, t).rss / n) + static_cast<double>(t.cols()) * std::log(n);
}

}  // namespace

// Each function's knots in turn (Ra, then a, then b, twice over), the one with the least BIC
// while the others stay: a few dozen small dense solves instead of every combination. Ra comes
// first, while b is still at its finest: Ra and b are nearly interchangeable on a short arc, and a
// b chosen first too coarse would leave its misfit for Ra to take up.
Knots ChooseKnots(const Solution& fine, const Layout& fine_layout, const std::vector<int> choices[3],
                  const MatrixXd& null_space) {
  Knots best = fine_layout.knots();
  int Knots::*const members[3] = {&Knots::radius, &Knots::axial, &Knots::runout};
  // The second round meets some trials of the first again (and each round its best so far): the
  // criterion is a function of the knots, so it is computed once for each.
  std::map<std::array<int, 3>, double> known;
  for (int round = 0; round < 2; ++round) {
    for (int f = 0; f < 3; ++f) {
      double least = std::numeric_limits<double>::infinity();
      int chosen = best.*members[f];
      for (const int k : choices[f]) {
        Knots trial = best;
        trial.*members[f] = k;
        const auto [entry, added] = known.try_emplace({trial.radius, trial.axial, trial.runout}, 0.0);
        if (added) entry->second = Bic(fine, fine_layout, trial, null_space);
        const double bic = entry->second;
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

}  // namespace arcwheel::fitting::internal
