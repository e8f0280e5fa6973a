#include "core/statistics.h"

#include <boost/math/distributions/chi_squared.hpp>

namespace arcwheel {

double ChiSquaredUpperTail(double chi2, double dof) {
  return boost::math::cdf(boost::math::complement(boost::math::chi_squared(dof), chi2));
}

}  // namespace arcwheel
