#include "processing/despike.h"

#include <fmt/core.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <deque>
#include <limits>
#include <utility>

#include "core/error.h"
#include "core/parallel.h"

namespace arcwheel::processing {
namespace {

template <typename T>
constexpr T kQuietNaN = std::numeric_limits<T>::quiet_NaN();

// Median of `values`, which it reorders; NaN when empty. An even count takes the mean of the two
// middle values.
double MedianInPlace(std::span<double> values) {
  const std::size_t n = values.size();
  if (n == 0) return kQuietNaN<double>;
  const auto middle = values.begin() + static_cast<std::ptrdiff_t>(n / 2);
  std::nth_element(values.begin(), middle, values.end());
  if (n % 2 == 1) return *middle;
  return 0.5 * (*std::max_element(values.begin(), middle) + *middle);
}

// The median rule itself: x is rejected when it is further than the threshold from the median of
// `window` (reordered).
bool FarFromMedian(double x, std::span<double> window, double threshold_mm) {
  const double median = MedianInPlace(window);
  return std::isfinite(median) && std::abs(x - median) > threshold_mm;
}

// ---- First median pass: a block screen instead of a sorted window per sample. ----
//
// For a full window of n = 2w+1 values around x, sorted v_0 <= ... <= v_2w, the rule rejects x
// when |x - v_w| > thr. Rounded subtraction is monotone, so fl(v_w - x) > thr exactly when at
// least w+1 values have fl(v - x) > thr, and fl(x - v_w) > thr (= fl(v_w - x) < -thr) exactly
// when at least w+1 have fl(v - x) < -thr: counting decides. The count is still used only as a
// filter (against a threshold a hair lower), and every candidate is decided by the exact rule.
// Before the count, the window's largest and smallest values skip the whole count for a sample
// that has no value beyond the threshold at all, which is all but the neighbours of spikes.

// Valid samples judged per block: the buffers stay within the first two cache levels.
constexpr std::size_t kBlock = 2048;
// The count's threshold is this much lower, relative, than the rule's.
constexpr double kScreenMargin = 1e-9;

// The valid samples of a stretch of the scan, widened to double, in order, with their indices.
struct ValidBlock {
  std::vector<double> values;
  std::vector<std::size_t> indices;
  std::size_t size = 0;
};

// Appends the valid samples of z[raw, to) to `block` until it holds `capacity`; returns where it
// stopped. Runs without invalid samples (nearly all of a scan) are copied in bulk.
template <typename T>
std::size_t FillBlock(std::span<const T> z, std::size_t raw, std::size_t to, std::size_t capacity,
                      ValidBlock& block) {
  constexpr std::size_t kRun = 64;
  while (raw < to && block.size < capacity) {
    const std::size_t take = std::min({kRun, to - raw, capacity - block.size});
    const T* source = z.data() + raw;
    std::size_t valid = 0;
    for (std::size_t k = 0; k < take; ++k) valid += std::isfinite(source[k]) ? 1 : 0;
    double* values = block.values.data() + block.size;
    std::size_t* indices = block.indices.data() + block.size;
    if (valid == take) {
      for (std::size_t k = 0; k < take; ++k) values[k] = source[k];
      for (std::size_t k = 0; k < take; ++k) indices[k] = raw + k;
    } else {
      std::size_t out = 0;
      for (std::size_t k = 0; k < take; ++k) {
        if (!std::isfinite(source[k])) continue;
        values[out] = source[k];
        indices[out++] = raw + k;
      }
    }
    block.size += valid;
    raw += take;
  }
  return raw;
}

// Positions [first, last) of `values`, each with its full window of w values on either side in
// the buffer, that some window value differs from by more than `screen_mm` (fl(v - x) > screen or
// < -screen). Largest and smallest values of each window by doubling: log2(2w+1) passes of
// branch-free max/min the compiler vectorises.
class ExtremeScreen {
 public:
  explicit ExtremeScreen(std::size_t capacity) : largest_(capacity), smallest_(capacity) {}

  void Suspects(const double* values, std::size_t first, std::size_t last, int w, double screen_mm,
                std::vector<std::size_t>& suspects) {
    const auto half = static_cast<std::size_t>(w);
    const std::size_t width = 2 * half + 1;
    const double* base = values + first - half;
    const std::size_t count = last - first + 2 * half;
    double* high = largest_.data();
    double* low = smallest_.data();
    // high[i], low[i]: extremes of base[i, i + span), for i + span <= count. Width >= 3, so the
    // first doubling reads the values themselves.
    for (std::size_t i = 0; i + 2 <= count; ++i) {
      high[i] = std::max(base[i], base[i + 1]);
      low[i] = std::min(base[i], base[i + 1]);
    }
    std::size_t span = 2;
    for (; 2 * span <= width; span *= 2) {
      for (std::size_t i = 0; i + 2 * span <= count; ++i) {
        high[i] = std::max(high[i], high[i + span]);
        low[i] = std::min(low[i], low[i + span]);
      }
    }
    const std::size_t overlap = width - span;  // [i, i + span) and [i + overlap, i + width)
    const double* centre = values + first;
    constexpr std::size_t kGroup = 32;
    for (std::size_t start = 0; start < last - first; start += kGroup) {
      const std::size_t stop = std::min(start + kGroup, last - first);
      double outside = 0.0;  // a double sum, which GCC vectorises (a bool or integer one it does not)
      for (std::size_t i = start; i < stop; ++i) outside += Outside(high, low, overlap, centre, i, screen_mm);
      if (outside == 0.0) continue;
      for (std::size_t i = start; i < stop; ++i) {
        if (Outside(high, low, overlap, centre, i, screen_mm) > 0.0) suspects.push_back(first + i);
      }
    }
  }

 private:
  // 1 or 2 when the window holds a value further than `screen_mm` from the centre, else 0.
  static double Outside(const double* high, const double* low, std::size_t overlap, const double* centre,
                        std::size_t i, double screen_mm) {
    const double largest = std::max(high[i], high[i + overlap]);
    const double smallest = std::min(low[i], low[i + overlap]);
    return (largest - centre[i] > screen_mm ? 1.0 : 0.0) + (smallest - centre[i] < -screen_mm ? 1.0 : 0.0);
  }

  std::vector<double> largest_;
  std::vector<double> smallest_;
};

// How many values of `window` have fl(v - x) above `screen_mm`, and how many below -screen_mm.
// Branch-free, counted in double: GCC vectorises it so (not with integer counts).
std::pair<double, double> CountOutside(std::span<const double> window, double x, double screen_mm) {
  double above = 0.0;
  double below = 0.0;
  for (const double v : window) {
    const double difference = v - x;
    above += difference > screen_mm ? 1.0 : 0.0;
    below += difference < -screen_mm ? 1.0 : 0.0;
  }
  return {above, below};
}

// The first pass over the valid samples with indices in [begin, end): their windows reach w
// valid samples beyond either end, as in one pass over the whole scan.
template <typename T>
class FirstMedianPass {
 public:
  FirstMedianPass(std::span<const T> z, int w, double threshold_mm)
      : z_(z),
        half_(static_cast<std::size_t>(w)),
        threshold_mm_(threshold_mm),
        screen_mm_(threshold_mm * (1.0 - kScreenMargin)),
        screen_(kBlock + 2 * half_),
        window_(2 * half_ + 1) {
    block_.values.resize(kBlock + 2 * half_);
    block_.indices.resize(kBlock + 2 * half_);
  }

  std::vector<std::size_t> Rejected(std::size_t begin, std::size_t end) {
    std::vector<std::size_t> rejected;
    const std::size_t to = ContextEnd(end);
    std::size_t raw = ContextBegin(begin);
    std::size_t next = 0;  // the first position not judged yet
    block_.size = 0;
    for (;;) {
      raw = FillBlock(z_, raw, to, block_.values.size(), block_);
      const bool last_block = raw == to;
      // Positions whose windows are whole in the buffer: all, once the stretch is read.
      const std::size_t ready = last_block ? block_.size : block_.size - half_;
      const std::size_t* indices = block_.indices.data();
      const std::size_t first =
          static_cast<std::size_t>(std::lower_bound(indices + next, indices + ready, begin) - indices);
      const std::size_t last =
          static_cast<std::size_t>(std::lower_bound(indices + first, indices + ready, end) - indices);
      Judge(first, last, rejected);
      if (last_block) break;
      // Keep the w values left of `ready` as its context, and the w not judged yet.
      const std::size_t keep_from = ready - half_;
      std::copy(block_.values.begin() + static_cast<std::ptrdiff_t>(keep_from),
                block_.values.begin() + static_cast<std::ptrdiff_t>(block_.size), block_.values.begin());
      std::copy(block_.indices.begin() + static_cast<std::ptrdiff_t>(keep_from),
                block_.indices.begin() + static_cast<std::ptrdiff_t>(block_.size), block_.indices.begin());
      block_.size -= keep_from;
      next = half_;
    }
    return rejected;
  }

 private:
  // The index of the w-th valid sample before `begin`, or 0 when there are fewer.
  std::size_t ContextBegin(std::size_t begin) const {
    std::size_t found = 0;
    while (begin > 0 && found < half_) found += std::isfinite(z_[--begin]) ? 1 : 0;
    return begin;
  }
  // One past the w-th valid sample from `end` on, or the scan's end when there are fewer.
  std::size_t ContextEnd(std::size_t end) const {
    for (std::size_t found = 0; end < z_.size() && found < half_; ++end)
      found += std::isfinite(z_[end]) ? 1 : 0;
    return end;
  }

  // Judges positions [first, last) of the block. A position with fewer than w values on a side
  // is at an end of the scan, where its window is cut short: it is judged by the rule directly.
  void Judge(std::size_t first, std::size_t last, std::vector<std::size_t>& rejected) {
    const std::size_t full_first = std::min(std::max(first, half_), last);
    const std::size_t full_last =
        std::max(std::min(last, block_.size - std::min(block_.size, half_)), full_first);
    for (std::size_t p = first; p < full_first; ++p) JudgeExactly(p, rejected);
    suspects_.clear();
    if (full_first < full_last) {
      screen_.Suspects(block_.values.data(), full_first, full_last, static_cast<int>(half_), screen_mm_,
                       suspects_);
    }
    for (const std::size_t p : suspects_) {
      const std::span<const double> window(block_.values.data() + p - half_, 2 * half_ + 1);
      const auto [above, below] = CountOutside(window, block_.values[p], screen_mm_);
      const auto majority = static_cast<double>(half_ + 1);
      if (above >= majority || below >= majority) JudgeExactly(p, rejected);
    }
    for (std::size_t p = full_last; p < last; ++p) JudgeExactly(p, rejected);
  }

  void JudgeExactly(std::size_t p, std::vector<std::size_t>& rejected) {
    const std::size_t from = p - std::min(p, half_);
    const std::size_t to = std::min(block_.size, p + half_ + 1);
    window_.assign(block_.values.begin() + static_cast<std::ptrdiff_t>(from),
                   block_.values.begin() + static_cast<std::ptrdiff_t>(to));
    if (FarFromMedian(block_.values[p], window_, threshold_mm_)) rejected.push_back(block_.indices[p]);
  }

  std::span<const T> z_;
  std::size_t half_;
  double threshold_mm_;
  double screen_mm_;
  ValidBlock block_;
  ExtremeScreen screen_;
  std::vector<std::size_t> suspects_;
  std::vector<double> window_;
};

// Scans shorter than this are judged on one worker.
constexpr std::size_t kParallelFrom = 100000;

// The first median pass on the two halves of the scan, one worker each; each half's windows reach
// into the other half, so the result is that of one pass over the whole scan.
template <typename T>
std::vector<std::size_t> FirstMedianRejections(std::span<const T> z, int w, double threshold_mm) {
  if (z.size() < kParallelFrom) return FirstMedianPass<T>(z, w, threshold_mm).Rejected(0, z.size());
  const std::size_t middle = z.size() / 2;
  std::array<std::vector<std::size_t>, 2> rejected;
  RunOnWorkers(2, [&](int half) {
    const bool lower = half == 0;
    rejected[static_cast<std::size_t>(half)] =
        FirstMedianPass<T>(z, w, threshold_mm).Rejected(lower ? 0 : middle, lower ? middle : z.size());
  });
  rejected[0].insert(rejected[0].end(), rejected[1].begin(), rejected[1].end());
  return std::move(rejected[0]);
}

// ---- The moving mean (the paper's improved moving average). ----

struct Sample {
  std::size_t index;
  double value;
};

// Streams the valid samples through a deque holding up to w samples on each side of the one
// being judged: no per-sample index array. Decisions use the original values; the rejected
// samples are changed only after the pass.
template <typename T>
std::vector<Sample> RejectByMeanOfOthers(std::span<const T> z, int w, double threshold_mm) {
  const auto half = static_cast<std::size_t>(w);
  std::deque<Sample> window;
  std::size_t centre = 0;
  double sum = 0.0;
  std::vector<Sample> rejected;  // index and the mean it was judged against
  const auto judge_next = [&] {
    const Sample& sample = window[centre];
    if (window.size() > 1) {
      const double mean_of_others = (sum - sample.value) / static_cast<double>(window.size() - 1);
      if (std::isfinite(mean_of_others) && std::abs(sample.value - mean_of_others) > threshold_mm) {
        rejected.push_back({sample.index, mean_of_others});
      }
    }
    ++centre;
    if (centre > half) {
      sum -= window.front().value;
      window.pop_front();
      --centre;
    }
  };
  for (std::size_t i = 0; i < z.size(); ++i) {
    if (!std::isfinite(z[i])) continue;
    window.push_back({i, static_cast<double>(z[i])});
    sum += static_cast<double>(z[i]);
    if (window.size() - centre > half) judge_next();
  }
  while (centre < window.size()) judge_next();
  return rejected;
}

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

// Runs the moving mean on the two halves of the scan on two workers. Each half streams w valid
// samples of the other half as context and keeps only its own decisions, so the result is that of
// one pass over the whole scan, but for the rounding of the running sum, which starts afresh at a
// half's context: the split is fixed at two halves so that no decision depends on the machine.
template <typename T>
std::vector<Sample> MeanRejectionsInParallel(std::span<const T> z, int w, double threshold_mm) {
  if (z.size() < kParallelFrom) return RejectByMeanOfOthers(z, w, threshold_mm);
  const std::size_t middle = z.size() / 2;
  std::array<std::vector<Sample>, 2> kept;
  RunOnWorkers(2, [&](int half) {
    const bool lower = half == 0;
    const std::size_t begin = lower ? 0 : ContextEdge(z, middle, w, -1);
    const std::size_t end = lower ? ContextEdge(z, middle - 1, w, +1) : z.size();
    for (Sample s : RejectByMeanOfOthers(z.subspan(begin, end - begin), w, threshold_mm)) {
      s.index += begin;
      if ((s.index < middle) == lower) kept[static_cast<std::size_t>(half)].push_back(s);
    }
  });
  kept[0].insert(kept[0].end(), kept[1].begin(), kept[1].end());
  return std::move(kept[0]);
}

// ---- Later median passes and the restore step: only near dropped samples. ----

// Up to w valid samples on each side of i (i itself left out), none further than 4w positions
// from it: across a dropout the wheel has turned on, and the readings there (several
// micrometres away where the arc radius varies with phase) would outvote i's own neighbours.
template <typename T>
class Neighbourhood {
 public:
  Neighbourhood(std::span<const T> z, int w) : z_(z), half_(static_cast<std::size_t>(w)) {}

  const std::vector<std::size_t>& Indices(std::size_t i) {
    const std::size_t reach = 4 * half_;
    indices_.clear();
    std::size_t left = 0;
    for (std::size_t k = i; k > 0 && i - k < reach && left < half_;) {
      if (std::isfinite(z_[--k])) {
        indices_.push_back(k);
        ++left;
      }
    }
    std::size_t right = 0;
    for (std::size_t k = i + 1; k < z_.size() && k - i <= reach && right < half_; ++k) {
      if (std::isfinite(z_[k])) {
        indices_.push_back(k);
        ++right;
      }
    }
    return indices_;
  }

  // Whether the median of i's neighbours, and of z[i] too when `with_self`, is further than the
  // threshold from x or not finite (no neighbours). Most windows judged here are the clean
  // neighbours of a spike: as in the first pass, when fewer than half of the n values (rounded
  // up) lie beyond x + thr, the median cannot (for even n it lies between the two middle values),
  // and likewise below, so no median is selected. Values beyond 1e300 mm, where the mean of the
  // two middle values could overflow, always go to the rule itself.
  bool FarFromMedianAround(std::size_t i, double x, bool with_self, double threshold_mm) {
    values_.clear();
    for (const std::size_t k : Indices(i)) values_.push_back(z_[k]);
    if (with_self) values_.push_back(z_[i]);
    if (values_.empty()) return true;
    const auto [above, below] = CountOutside(values_, x, threshold_mm * (1.0 - kScreenMargin));
    const auto half_or_more = static_cast<double>((values_.size() + 1) / 2);
    const auto moderate = [](double v) { return std::abs(v) <= 1e300; };
    if (above < half_or_more && below < half_or_more && moderate(x) &&
        std::all_of(values_.begin(), values_.end(), moderate)) {
      return false;
    }
    const double median = MedianInPlace(values_);
    return !std::isfinite(median) || std::abs(x - median) > threshold_mm;
  }

 private:
  std::span<const T> z_;
  std::size_t half_;
  std::vector<std::size_t> indices_;
  std::vector<double> values_;
};

// The neighbours (as Neighbourhood::Indices) of any of `removed`, sorted and unique.
template <typename T>
std::vector<std::size_t> SamplesNear(Neighbourhood<T>& neighbourhood,
                                     const std::vector<std::size_t>& removed) {
  std::vector<std::size_t> near;
  for (const std::size_t r : removed) {
    const std::vector<std::size_t>& found = neighbourhood.Indices(r);
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
  std::vector<std::pair<std::size_t, T>> dropped;  // index, reading
  std::vector<std::size_t> newly = FirstMedianRejections(std::span<const T>(z), w, threshold_mm);
  Neighbourhood<T> neighbourhood(z, w);
  for (int pass = 1; !newly.empty(); ++pass) {
    for (const std::size_t i : newly) {
      dropped.emplace_back(i, z[i]);
      z[i] = kQuietNaN<T>;
    }
    if (pass == kMaxPasses) break;
    std::vector<std::size_t> next;
    for (const std::size_t i : SamplesNear(neighbourhood, newly)) {
      if (neighbourhood.FarFromMedianAround(i, z[i], true, threshold_mm)) next.push_back(i);
    }
    newly = std::move(next);
  }
  // Decided for all before any comes back, so that none is judged with a restored one's help.
  std::vector<char> agrees(dropped.size(), 0);
  for (std::size_t k = 0; k < dropped.size(); ++k) {
    agrees[k] = !neighbourhood.FarFromMedianAround(dropped[k].first, dropped[k].second, false, threshold_mm);
  }
  for (std::size_t k = 0; k < dropped.size(); ++k) {
    if (agrees[k]) {
      z[dropped[k].first] = dropped[k].second;
    } else {
      result.indices.push_back(dropped[k].first);
    }
  }
  std::sort(result.indices.begin(), result.indices.end());
}

template <typename T>
void DespikeByMovingMean(std::span<T> z, int w, double threshold_mm, DespikeResult& result) {
  for (const Sample& s : MeanRejectionsInParallel(std::span<const T>(z), w, threshold_mm)) {
    z[s.index] = static_cast<T>(s.value);  // replaced by the mean of the others, as in the paper
    result.indices.push_back(s.index);
  }
}

template <typename T>
DespikeResult DespikeSamples(std::span<T> z_mm, double noise_sigma_mm, const DespikeOptions& options) {
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

DespikeResult Despike(std::span<double> z_mm, double noise_sigma_mm, const DespikeOptions& options) {
  return DespikeSamples(z_mm, noise_sigma_mm, options);
}

DespikeResult Despike(std::span<float> z_mm, double noise_sigma_mm, const DespikeOptions& options) {
  return DespikeSamples(z_mm, noise_sigma_mm, options);
}

}  // namespace arcwheel::processing
