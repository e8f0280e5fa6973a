#include "processing/despike.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/error.h"

namespace arcwheel::processing {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

std::vector<std::size_t> ValidIndices(std::span<const double> z) {
  std::vector<std::size_t> valid;
  valid.reserve(z.size());
  for (std::size_t i = 0; i < z.size(); ++i) {
    if (std::isfinite(z[i])) valid.push_back(i);
  }
  return valid;
}

// A sorted window of the last 2w+1 values: O(w) insert and erase, which for w <= 50 beats a
// heap-based running median in practice.
class SortedWindow {
 public:
  void Insert(double value) { values_.insert(std::lower_bound(values_.begin(), values_.end(), value), value); }
  void Erase(double value) { values_.erase(std::lower_bound(values_.begin(), values_.end(), value)); }
  [[nodiscard]] double Median() const {
    const std::size_t n = values_.size();
    return n % 2 == 1 ? values_[n / 2] : 0.5 * (values_[n / 2 - 1] + values_[n / 2]);
  }

 private:
  std::vector<double> values_;
};

void DespikeByMedian(std::span<double> z, const std::vector<std::size_t>& valid, int w, double threshold_mm,
                     DespikeResult& result) {
  const std::size_t n = valid.size();
  const auto half = static_cast<std::size_t>(w);
  // Decisions use the original values: rejected samples become NaN only after the pass.
  SortedWindow window;
  std::size_t in_end = 0;  // window covers valid[in_begin, in_end)
  std::size_t in_begin = 0;
  std::vector<std::size_t> rejected;
  for (std::size_t k = 0; k < n; ++k) {
    const std::size_t want_begin = k >= half ? k - half : 0;
    const std::size_t want_end = std::min(n, k + half + 1);
    while (in_end < want_end) window.Insert(z[valid[in_end++]]);
    while (in_begin < want_begin) {
      window.Erase(z[valid[in_begin]]);
      ++in_begin;
    }
    if (std::abs(z[valid[k]] - window.Median()) > threshold_mm) rejected.push_back(valid[k]);
  }
  for (const std::size_t i : rejected) z[i] = kNaN;
  result.indices = std::move(rejected);
}

void DespikeByMovingMean(std::span<double> z, const std::vector<std::size_t>& valid, int w, double threshold_mm,
                         DespikeResult& result) {
  const std::size_t n = valid.size();
  const auto half = static_cast<std::size_t>(w);
  std::vector<double> replaced;
  std::vector<std::size_t> rejected;
  double sum = 0.0;
  std::size_t begin = 0;
  std::size_t end = 0;
  for (std::size_t k = 0; k < n; ++k) {
    const std::size_t want_begin = k >= half ? k - half : 0;
    const std::size_t want_end = std::min(n, k + half + 1);
    while (end < want_end) sum += z[valid[end++]];
    while (begin < want_begin) sum -= z[valid[begin++]];
    const double others = static_cast<double>(end - begin - 1);
    if (others < 1) continue;
    const double mean_of_others = (sum - z[valid[k]]) / others;
    if (std::abs(z[valid[k]] - mean_of_others) > threshold_mm) {
      rejected.push_back(valid[k]);
      replaced.push_back(mean_of_others);
    }
  }
  for (std::size_t r = 0; r < rejected.size(); ++r) z[rejected[r]] = replaced[r];
  result.indices = std::move(rejected);
}

}  // namespace

std::vector<std::string> DespikeOptions::Problems() const {
  std::vector<std::string> problems;
  if (window_half_width < 1 || window_half_width > 50) {
    problems.push_back("despike window_half_width = " + std::to_string(window_half_width) + " violates 1..50");
  }
  if (!(threshold_sigmas > 0)) problems.push_back("despike threshold_sigmas must be > 0");
  if (!(min_threshold_um >= 0)) problems.push_back("despike min_threshold_um must be >= 0");
  if (!std::isfinite(threshold_um)) problems.push_back("despike threshold_um must be finite");
  return problems;
}

DespikeMethod ParseDespikeMethod(const std::string& name) {
  if (name == "median") return DespikeMethod::kMedian;
  if (name == "moving-mean") return DespikeMethod::kMovingMean;
  if (name == "none") return DespikeMethod::kNone;
  throw Error(ErrorCode::kInvalidOption, "processing.despike",
              "unknown method '" + name + "' (expected median, moving-mean or none)");
}

std::string DespikeMethodName(DespikeMethod method) {
  switch (method) {
    case DespikeMethod::kMedian: return "median";
    case DespikeMethod::kMovingMean: return "moving-mean";
    case DespikeMethod::kNone: return "none";
  }
  return "none";
}

DespikeResult Despike(std::span<double> z_mm, double noise_sigma_mm, const DespikeOptions& options) {
  if (const auto problems = options.Problems(); !problems.empty()) {
    throw Error(ErrorCode::kInvalidOption, "processing.despike", problems.front());
  }
  DespikeResult result;
  result.threshold_um = options.threshold_um > 0
                            ? options.threshold_um
                            : std::max(options.min_threshold_um, options.threshold_sigmas * noise_sigma_mm * 1000.0);
  if (options.method == DespikeMethod::kNone) return result;
  const std::vector<std::size_t> valid = ValidIndices(z_mm);
  const double threshold_mm = result.threshold_um / 1000.0;
  if (options.method == DespikeMethod::kMedian) {
    DespikeByMedian(z_mm, valid, options.window_half_width, threshold_mm, result);
  } else {
    DespikeByMovingMean(z_mm, valid, options.window_half_width, threshold_mm, result);
  }
  result.rejected = result.indices.size();
  return result;
}

}  // namespace arcwheel::processing
