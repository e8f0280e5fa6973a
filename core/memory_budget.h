#pragma once
// The memory budget of one run. arcwheel runs on a 24 GiB machine beside other work, and a size
// that cannot fit (a path spacing of 1e-4 mm, a toolpath step of 1e-6 mm, a map of 1e9 nodes)
// used to run for minutes and end in std::bad_alloc. Each stage therefore estimates, from its job
// and the headers of its input files, the largest arrays the run will hold, and refuses up front
// (exit status 3) any size that needs more than this budget, naming the key, the size it implies
// and the limit. The per-item costs are the stages' own measured figures (docs/polishing.md,
// docs/grinding.md).

#include <fmt/format.h>

#include <cstddef>
#include <optional>
#include <string>
#include <string_view>

namespace arcwheel {

// 4 GiB: a sixth of the machine, so that a run leaves room for the others, and ten times what
// the largest jobs in the tests and benchmarks need.
inline constexpr double kMemoryBudgetBytes = 4.0 * 1024.0 * 1024.0 * 1024.0;

// Empty when `count` items of `bytes_per_item` bytes each fit the budget. Otherwise one line in
// the form of the options' Problems(), e.g. for setting = "path.point_spacing_mm = 0.0001":
//   "path.point_spacing_mm = 0.0001 violates the memory budget: it implies 3.6e+09 dwell points
//    x 700 B = 2.5e+12 B, over the 4 GiB (4294967296 B) of one run"
// A count that is NaN or infinite (a spacing that underflows) is over the budget too.
[[nodiscard]] inline std::optional<std::string> MemoryBudgetProblem(std::string_view setting, double count,
                                                                    std::string_view items,
                                                                    double bytes_per_item) {
  const double bytes = count * bytes_per_item;
  if (bytes <= kMemoryBudgetBytes) return std::nullopt;
  return fmt::format(
      "{} violates the memory budget: it implies {:.3g} {} x {:g} B = {:.3g} B, over the {:g} GiB "
      "({:.0f} B) of one run",
      setting, count, items, bytes_per_item, bytes, kMemoryBudgetBytes / (1024.0 * 1024.0 * 1024.0),
      kMemoryBudgetBytes);
}

}  // namespace arcwheel
