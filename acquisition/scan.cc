#include "acquisition/scan.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "core/error.h"

namespace arcwheel::acquisition {
namespace {

constexpr const char* kScanStage = "acquisition.validate";

[[noreturn]] void Refuse(const Scan& scan, const std::string& problem) {
  throw Error(ErrorCode::kBadInput, kScanStage, "'" + scan.path + "': " + problem);
}

std::string Number(double value) {
  char text[32];
  std::snprintf(text, sizeof text, "%.9g", value);
  return text;
}

// Axial positions beyond 1 km are a unit mistake; there the spacing of doubles (1.2e-10 mm at
// 1e6 mm) starts to eat into the nanometres the arc fits resolve, and at 1e15 mm it is 0.125 mm.
constexpr double kMaxAxialMm = 1e6;

void CheckColumn(const Scan& scan, const std::vector<double>& column, const char* name) {
  if (column.empty()) return;
  if (column.size() != scan.size()) {
    Refuse(scan, std::string("column '") + name + "' has " + std::to_string(column.size()) +
                     " values but 'z' has " + std::to_string(scan.size()));
  }
  for (size_t i = 0; i < column.size(); ++i) {
    if (!std::isfinite(column[i])) {
      Refuse(scan, std::string("column '") + name + "' is not finite at sample " + std::to_string(i));
    }
  }
}

void CheckIncreasing(const Scan& scan, const std::vector<double>& column, const char* name) {
  for (size_t i = 1; i < column.size(); ++i) {
    if (!(column[i] > column[i - 1])) {
      Refuse(scan, std::string("column '") + name + "' does not increase at sample " + std::to_string(i) +
                       " (" + Number(column[i - 1]) + " then " + Number(column[i]) + ")");
    }
  }
}

// An encoder wrapped at 2 pi rather than 360 steps back by less than half a turn in degrees, so
// it reads as an angle that does not increase: say what it looks like.
std::string RadiansHint(const std::vector<double>& angle) {
  const auto [low, high] = std::minmax_element(angle.begin(), angle.end());
  constexpr double kTwoPi = 6.283185307179586;
  if (*low >= 0.0 && *high <= kTwoPi * (1.0 + 1e-9)) {
    return "; every value lies within 0 .. 2 pi: radians? The angle column is in degrees";
  }
  return "";
}

void CheckPositive(const Scan& scan, const std::optional<double>& value, const char* name) {
  if (value && !(*value > 0.0 && std::isfinite(*value))) {
    Refuse(scan, std::string(name) + " must be positive and finite, got " + Number(*value));
  }
}

}  // namespace

FloatColumn& FloatColumn::operator=(FloatColumn&& other) noexcept {
  if (this == &other) return *this;
  // A vector's move keeps its buffer, so the view stays valid.
  owned_ = std::move(other.owned_);
  owner_ = std::move(other.owner_);
  values_ = other.values_;
  other.owned_ = {};
  other.owner_.reset();
  other.values_ = {};
  return *this;
}

size_t Scan::CountValid() const {
  return VisitReadings(*this, [](const auto& z) {
    return static_cast<size_t>(std::count_if(z.begin(), z.end(), [](double v) { return std::isfinite(v); }));
  });
}

void Scan::WidenToDouble() {
  if (!holds_float()) return;
  z_mm.assign(z_float_mm.begin(), z_float_mm.end());
  z_float_mm.Release();  // 400 MB at 1e8 samples
}

void ValidateScan(const Scan& scan) {
  const ScanMetadata& meta = scan.metadata;
  if (scan.size() == 0) Refuse(scan, "holds no samples");
  CheckColumn(scan, scan.t_s, "t");
  CheckColumn(scan, scan.angle_deg, "angle");
  CheckColumn(scan, scan.y_mm, "y");
  CheckPositive(scan, meta.spindle_rpm, "spindle_rpm");
  CheckPositive(scan, meta.feed_mm_per_min, "feed_mm_per_min");
  CheckPositive(scan, meta.sample_period_s, "sample_period_s");
  // A sensor's own export rarely carries the settings: say which key supplies the missing one.
  const auto lacks = [&](const char* key, const char* column) {
    Refuse(scan, std::string("lacks ") + key + " (and has no " + column + " column): give \"" + key +
                     "\" in the file's metadata or in --scan-settings SETTINGS.json");
  };
  if (!scan.has_encoder() && !meta.spindle_rpm) lacks("spindle_rpm", "angle");
  if (!scan.has_time() && !meta.sample_period_s) lacks("sample_period_s", "t");
  if (!scan.has_axial() && !meta.feed_mm_per_min) lacks("feed_mm_per_min", "y");
  if (meta.radius_sign != 1.0 && meta.radius_sign != -1.0) {
    Refuse(scan, "radius_sign must be +1 or -1, got " + Number(meta.radius_sign));
  }
  CheckIncreasing(scan, scan.t_s, "t");

  const auto [i0, i1] = VisitReadings(scan, [&](const auto& z) {
    const auto first = std::find_if(z.begin(), z.end(), [](double v) { return std::isfinite(v); });
    if (first == z.end()) Refuse(scan, "has no valid samples");
    const auto last = std::find_if(z.rbegin(), z.rend(), [](double v) { return std::isfinite(v); });
    return std::pair<size_t, size_t>(static_cast<size_t>(first - z.begin()),
                                     z.size() - 1 - static_cast<size_t>(last - z.rbegin()));
  });

  const auto time_at = [&](size_t i) {
    return scan.has_time() ? scan.t_s[i] : static_cast<double>(i) * *meta.sample_period_s;
  };
  const double duration_s = time_at(i1) - time_at(i0);
  // An encoder may be wrapped; its coverage is judged after unwrapping in processing, so here
  // only the nominal speed (when given) or the sample count can say "too short".
  double turns = 0.0;
  if (scan.has_encoder()) {
    double unwrapped = 0.0;
    for (size_t i = i0 + 1; i <= i1; ++i) {
      double step = scan.angle_deg[i] - scan.angle_deg[i - 1];
      if (step < -180.0) step += 360.0;
      if (step <= 0.0) {
        Refuse(scan, "column 'angle' does not increase at sample " + std::to_string(i) + " (" +
                         Number(scan.angle_deg[i - 1]) + " then " + Number(scan.angle_deg[i]) + ")" +
                         RadiansHint(scan.angle_deg));
      }
      unwrapped += step;
    }
    turns = unwrapped / 360.0;
  } else {
    turns = *meta.spindle_rpm * duration_s / 60.0;
  }
  if (turns < 2.0) {
    Refuse(scan, "its valid samples cover " + Number(turns) + " turns of the wheel; at least 2 are needed");
  }
  const double axial_span_mm =
      scan.has_axial() ? std::abs(scan.y_mm[i1] - scan.y_mm[i0]) : *meta.feed_mm_per_min * duration_s / 60.0;
  double farthest_mm = std::abs(meta.start_y_mm) + (scan.has_axial() ? 0.0 : axial_span_mm);
  for (const double y : scan.y_mm) farthest_mm = std::max(farthest_mm, std::abs(y));
  if (farthest_mm > kMaxAxialMm) {
    Refuse(scan, "its axial positions reach " + Number(farthest_mm) + " mm; beyond " + Number(kMaxAxialMm) +
                     " mm a double no longer resolves the nanometres the arc fits need (a unit mistake?)");
  }
  const double pitch_mm = axial_span_mm / turns;
  if (!(axial_span_mm >= 3.0 * pitch_mm) || !(pitch_mm > 0.0)) {
    Refuse(scan, "its valid samples span " + Number(axial_span_mm) +
                     " mm along the axis, under 3 helix pitches (" + Number(3.0 * pitch_mm) + " mm)");
  }
}

}  // namespace arcwheel::acquisition
