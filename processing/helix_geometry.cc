#include "processing/helix_geometry.h"

#include <algorithm>
#include <cmath>

#include "core/error.h"

namespace arcwheel::processing {

HelixGeometry::HelixGeometry(const acquisition::Scan& scan, double spindle_rpm) : size_(scan.size()) {
  const acquisition::ScanMetadata& meta = scan.metadata;
  if (scan.has_time()) t_s_ = &scan.t_s;
  if (scan.has_axial()) y_mm_ = &scan.y_mm;
  sample_period_s_ = meta.sample_period_s.value_or(0.0);
  // Whole turns of the start phase change nothing but the digits left for the phase's fraction
  // (at 1e18 deg the spacing of doubles is 128 deg); fmod takes them off exactly.
  start_phase_deg_ = std::fmod(meta.start_phase_deg, 360.0);
  start_y_mm_ = meta.start_y_mm;
  feed_mm_per_min_ = meta.feed_mm_per_min.value_or(0.0);
  rpm_ = spindle_rpm;
  if (scan.has_encoder()) {
    // Encoder readings may be wrapped to [0, 360): add a turn at every backward jump.
    unwrapped_deg_.resize(size_);
    double turns = 0.0;
    unwrapped_deg_[0] = scan.angle_deg[0];
    for (std::size_t i = 1; i < size_; ++i) {
      const double step = scan.angle_deg[i] - scan.angle_deg[i - 1];
      if (step < -180.0) turns += 360.0;
      unwrapped_deg_[i] = scan.angle_deg[i] + turns;
      if (!(unwrapped_deg_[i] > unwrapped_deg_[i - 1])) {
        throw Error(ErrorCode::kBadInput, "processing.unwrap",
                    "'" + scan.path + "': encoder angle does not increase at sample " + std::to_string(i));
      }
    }
    const double duration_s = TimeAt(size_ - 1);
    if (duration_s > 0) rpm_ = (unwrapped_deg_.back() - unwrapped_deg_.front()) / 6.0 / duration_s;
  }
  const double total_turns = (PhaseAt(size_ - 1) - PhaseAt(0)) / 360.0;
  pitch_mm_ = total_turns > 0 ? (AxialAt(size_ - 1) - AxialAt(0)) / total_turns : 0.0;
}

double HelixGeometry::AxialAtPhase(double u_deg) const {
  if (unwrapped_deg_.empty() && t_s_ == nullptr) {
    const double t = (u_deg - start_phase_deg_) / (6.0 * rpm_);
    if (y_mm_ == nullptr) return start_y_mm_ + feed_mm_per_min_ * t / 60.0;
  }
  // General case: find the samples around u and interpolate their axial positions.
  std::size_t lo = 0;
  std::size_t hi = size_ - 1;
  if (u_deg <= PhaseAt(0)) return AxialAt(0);
  if (u_deg >= PhaseAt(hi)) return AxialAt(hi);
  while (hi - lo > 1) {
    const std::size_t mid = lo + (hi - lo) / 2;
    (PhaseAt(mid) <= u_deg ? lo : hi) = mid;
  }
  const double f = (u_deg - PhaseAt(lo)) / (PhaseAt(hi) - PhaseAt(lo));
  return AxialAt(lo) + f * (AxialAt(hi) - AxialAt(lo));
}

}  // namespace arcwheel::processing
