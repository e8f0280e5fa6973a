#include "processing/despike.h"

#include <fmt/core.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <deque>
#include <limits>

#include "core/error.h"
#include "core/parallel.h"

namespace arcwheel::processing {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// A sorted window of the last 2w+1 values: O(w) insert and erase, which for w <= 50 beats a
// heap-based running median in practice.
class SortedWindow {
 public:
  void Insert(double value) {
    values_.insert(std::lower_bound(values_.begin(), values_.end(), value), value);
  }
  void Erase(double value) { values_.erase(std::lower_bound(values_.begin(), values_.end(), value)); }
  [[nodiscard]] double Median() const {
    const std::size_t n = values_.size();
    return n % 2 == 1 ? values_[n / 2] : 0.5 * (values_[n / 2 - 1] + values_[n / 2]);
  }

 private:
  std::vector<double> values_;
};

struct Sample {
  std::size_t index;
  double value;
};

// Both filters stream the valid samples through a deque holding up to w samples on each side of
// the one being judged: no per-sample index array, so a 1e7-sample scan needs no more memory
// than its own readings. Decisions use the original values; the rejected samples are changed
// only after the pass.
template <typename Statistic, typename T>
std::vector<Sample> Reject(std::span<const T> z, int w, double threshold_mm, Statistic& statistic) {
  const auto half = static_cast<std::size_t>(w);
  std::deque<Sample> window;
  std::size_t centre = 0;
  std::vector<Sample> rejected;  // index and the statistic it was judged against
  const auto judge_next = [&] {
    const Sample& sample = window[centre];
    const double reference = statistic.Reference(sample.value);
    if (std::isfinite(reference) && std::abs(sample.value - reference) > threshold_mm) {
      rejected.push_back({sample.index, reference});
    }
    ++centre;
    if (centre > half) {
      statistic.Remove(window.front().value);
      window.pop_front();
      --centre;
    }
  };
  for (std::size_t i = 0; i < z.size(); ++i) {
    if (!std::isfinite(z[i])) continue;
    window.push_back({i, z[i]});
    statistic.Add(z[i]);
    if (window.size() - centre > half) judge_next();
  }
  while (centre < window.size()) judge_next();
  return rejected;
}

// Median of the whole window (Hampel-type, burst-safe).
struct WindowMedian {
  SortedWindow sorted;
  void Add(double v) { sorted.Insert(v); }
  void Remove(double v) { sorted.Erase(v); }
  [[nodiscard]] double Reference(double /*centre*/) const { return sorted.Median(); }
};

// Mean of the other samples in the window (the paper's improved moving average).
struct WindowMeanOfOthers {
  double sum = 0.0;
  std::size_t count = 0;
  void Add(double v) {
    sum += v;
    ++count;
  }
  void Remove(double v) {
    sum -= v;
    --count;
  }
  [[nodiscard]] double Reference(double centre) const {
    return count > 1 ? (sum - centre) / static_cast<double>(count - 1)
                     : std::numeric_limits<double>::quiet_NaN();
  }
};

// Index where the w-th valid sample before (direction -1) or after (+1) `from` lies, clamped.
template <typename T>
std::size_t ContextEdge(std::span<const T> z, std::size_t from, int w, int direction) {
  std::size_t i = from;
  for (int found = 0; found <= w;) {
    if (direction < 0 ? i == 0 : i + 1 >= z.size()) return direction < 0 ? 0 : z.size();
    i = direction < 0 ? i - 1 : i + 1;
    if (std::isfinite(z[i])) ++found;
  }
  return direction < 0 ? i : i + 1;
}

// Runs Reject on the two halves of the scan on two workers. Each half streams w valid samples of
// the other half as context and keeps only its own decisions, so the result is that of one pass
// over the whole scan, but for the rounding of the running mean's sum, which starts afresh at a
// half's context: the split is fixed at two halves so that no decision depends on the machine.
template <typename Statistic, typename T>
std::vector<Sample> RejectInParallel(std::span<const T> z, int w, double threshold_mm) {
  const std::size_t middle = z.size() / 2;
  if (z.size() < 100000) {
    Statistic statistic;
    return Reject(z, w, threshold_mm, statistic);
  }
  std::array<std::vector<Sample>, 2> kept;
  RunOnWorkers(2, [&](int half) {
    const bool lower = half == 0;
    const std::size_t begin = lower ? 0 : ContextEdge(z, middle, w, -1);
    const std::size_t end = lower ? ContextEdge(z, middle - 1, w, +1) : z.size();
    Statistic statistic;
    for (Sample s : Reject(z.subspan(begin, end - begin), w, threshold_mm, statistic)) {
      s.index += begin;
      if ((s.index < middle) == lower) kept[static_cast<std::size_t>(half)].push_back(s);
    }
  });
  kept[0].insert(kept[0].end(), kept[1].begin(), kept[1].end());
  return std::move(kept[0]);
}

// Up to w valid samples on each side of i (i itself left out), none further than 4w positions
// from it: across a dropout the wheel has turned on, and the readings there (several
// micrometres away where the arc radius varies with phase) would outvote i's own neighbours.
template <typename T>
std::vector<std::size_t> NeighbourIndices(std::span<const T> z, std::size_t i, int w) {
  const std::size_t reach = 4 * static_cast<std::size_t>(w);
  std::vector<std::size_t> found;
  std::size_t left = 0;
  for (std::size_t k = i; k > 0 && i - k < reach && left < static_cast<std::size_t>(w);) {
    if (std::isfinite(z[--k])) {
      found.push_back(k);
      ++left;
    }
  }
  std::size_t right = 0;
  for (std::size_t k = i + 1; k < z.size() && k - i <= reach && right < static_cast<std::size_t>(w); ++k) {
    if (std::isfinite(z[k])) {
      found.push_back(k);
      ++right;
    }
  }
  return found;
}

template <typename T>
std::vector<double> Neighbours(std::span<const T> z, std::size_t i, int w) {
  std::vector<double> values;
  for (const std::size_t k : NeighbourIndices(z, i, w)) values.push_back(z[k]);
  return values;
}

double MedianOf(std::vector<double> values) {
  if (values.empty()) return kNaN;
  SortedWindow sorted;
  for (const double v : values) sorted.Insert(v);
  return sorted.Median();
}

// The neighbours (as NeighbourIndices) of any of `removed`, sorted and unique.
template <typename T>
std::vector<std::size_t> SamplesNear(std::span<const T> z, const std::vector<std::size_t>& removed, int w) {
  std::vector<std::size_t> near;
  for (const std::size_t r : removed) {
    const std::vector<std::size_t> found = NeighbourIndices(z, r, w);
    near.insert(near.end(), found.begin(), found.end());
  }
  std::sort(near.begin(), near.end());
  near.erase(std::unique(near.begin(), near.end()), near.end());
  return near;
}

// A window in which spikes are the majority (a 5-sample burst beside an isolated spike) has a
// spike for its median, so one pass keeps a spike there and may drop a good sample. Later passes
// judge again, without the samples already dropped, every sample whose window held one; they
// stop when nothing more is dropped. Last, every dropped sample is judged against its kept
// neighbours, and the good ones an early, spiked median condemned come back.
template <typename T>
void DespikeByMedian(std::span<T> z, int w, double threshold_mm, DespikeResult& result) {
  constexpr int kMaxPasses = 8;
  std::vector<std::pair<std::size_t, double>> dropped;  // index, reading
  std::vector<std::size_t> newly;
  const std::span<const T> view(z);
  for (const Sample& s : RejectInParallel<WindowMedian>(view, w, threshold_mm)) newly.push_back(s.index);
  for (int pass = 1; !newly.empty(); ++pass) {
    for (const std::size_t i : newly) {
      dropped.emplace_back(i, z[i]);
      z[i] = static_cast<T>(kNaN);
    }
    if (pass == kMaxPasses) break;
    std::vector<std::size_t> next;
    for (const std::size_t i : SamplesNear(view, newly, w)) {
      std::vector<double> window = Neighbours(view, i, w);
      window.push_back(z[i]);
      if (std::abs(z[i] - MedianOf(std::move(window))) > threshold_mm) next.push_back(i);
    }
    newly = std::move(next);
  }
  // Decided for all before any comes back, so that none is judged with a restored one's help.
  std::vector<char> agrees(dropped.size(), 0);
  for (std::size_t k = 0; k < dropped.size(); ++k) {
    const double median = MedianOf(Neighbours(view, dropped[k].first, w));
    agrees[k] = std::isfinite(median) && std::abs(dropped[k].second - median) <= threshold_mm;
  }
  for (std::size_t k = 0; k < dropped.size(); ++k) {
    if (agrees[k]) {
      z[dropped[k].first] = static_cast<T>(dropped[k].second);
    } else {
      result.indices.push_back(dropped[k].first);
    }
  }
  std::sort(result.indices.begin(), result.indices.end());
}

template <typename T>
void DespikeByMovingMean(std::span<T> z, int w, double threshold_mm, DespikeResult& result) {
  for (const Sample& s : RejectInParallel<WindowMeanOfOthers>(std::span<const T>(z), w, threshold_mm)) {
    z[s.index] = static_cast<T>(s.value);  // replaced by the mean of the others, as in the paper
    result.indices.push_back(s.index);
  }
}

}  // namespace

std::vector<std::string> DespikeOptions::Problems() const {
  std::vector<std::string> problems;
  if (window_half_width < 1 || window_half_width > 50)
    problems.push_back(fmt::format("--despike-window = {} violates 1..50", window_half_width));
  if (!(threshold_sigmas > 0))
    problems.push_back(fmt::format("--despike-sigmas = {} violates > 0", threshold_sigmas));
  if (!(min_threshold_um >= 0))
    problems.push_back(fmt::format("despike.min_threshold_um = {} violates >= 0", min_threshold_um));
  if (!std::isfinite(threshold_um))
    problems.push_back(fmt::format("--despike-threshold-um = {} violates finite", threshold_um));
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
    case DespikeMethod::kMedian:
      return "median";
    case DespikeMethod::kMovingMean:
      return "moving-mean";
    case DespikeMethod::kNone:
      return "none";
  }
  return "none";
}

namespace {

template <typename T>
DespikeResult DespikeReadings(std::span<T> z_mm, double noise_sigma_mm, const DespikeOptions& options) {
  ThrowIfProblems(ErrorCode::kInvalidOption, "processing.despike", options.Problems());
  DespikeResult result;
  result.threshold_um =
      options.threshold_um > 0
          ? options.threshold_um
          : std::max(options.min_threshold_um, options.threshold_sigmas * noise_sigma_mm * 1000.0);
  if (options.method == DespikeMethod::kNone) return result;
  const double threshold_mm = result.threshold_um / 1000.0;
  if (options.method == DespikeMethod::kMedian) {
    DespikeByMedian(z_mm, options.window_half_width, threshold_mm, result);
  } else {
    DespikeByMovingMean(z_mm, options.window_half_width, threshold_mm, result);
  }
  result.rejected = result.indices.size();
  return result;
}

}  // namespace

DespikeResult Despike(std::span<double> z_mm, double noise_sigma_mm, const DespikeOptions& options) {
  return DespikeReadings(z_mm, noise_sigma_mm, options);
}

DespikeResult Despike(std::span<float> z_mm, double noise_sigma_mm, const DespikeOptions& options) {
  return DespikeReadings(z_mm, noise_sigma_mm, options);
}

}  // namespace arcwheel::processing
