#pragma once

#include <limits>

namespace arcwheel {

// A quiet NaN marks a value that was not measured or could not be estimated (a missing reading,
// an empty node), so that it propagates instead of passing for a number.
inline constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

}  // namespace arcwheel
