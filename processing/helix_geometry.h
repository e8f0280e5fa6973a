#pragma once
// Where each sample lies on the helix (formats.md section 1, method.md A.1-A.3): its unwrapped
// phase u (deg, continuous across turns: u = c + 360 k on turn k) and its axial position y (mm).

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "acquisition/scan.h"

namespace arcwheel::processing {

enum class PhaseSource { kNominal, kEstimated, kEncoder };

// Per-sample arithmetic of the map's and the model's cells, exactly as the library calls give it
// but without them (a call per sample cost as much as the rest of a sample's work).

// std::lround(x): the fraction of a double is exact, so this rounds half away from zero as lround.
[[nodiscard]] inline long RoundHalfAway(double x) {
  const double magnitude = std::abs(x);
  auto k = static_cast<long>(magnitude);
  if (magnitude - static_cast<double>(k) >= 0.5) ++k;
  return x < 0.0 ? -k : k;
}

// The phase within the turn, as std::fmod(u, 360) (+ 360 below zero) gives it: u - 360 q is exact
// for the right whole number of turns q (Sterbenz), so only q is guessed, and corrected when the
// guess was one off.
[[nodiscard]] inline double PhaseInTurn(double unwrapped_deg) {
  if (!(unwrapped_deg >= 0.0 && unwrapped_deg < 1e15)) {
    const double c = std::fmod(unwrapped_deg, 360.0);
    return c < 0.0 ? c + 360.0 : c;
  }
  const auto turns = static_cast<double>(static_cast<std::int64_t>(unwrapped_deg * (1.0 / 360.0)));
  double c = unwrapped_deg - 360.0 * turns;
  if (c < 0.0) c = unwrapped_deg - 360.0 * (turns - 1.0);
  if (c >= 360.0) c = unwrapped_deg - 360.0 * (turns + 1.0);
  return c;
}

class HelixGeometry {
 public:
  // From the scan's own columns where present, else from its settings with `spindle_rpm`
  // (the speed the processing decided on; ignored when the scan has an encoder column).
  // Throws Error{kBadInput} if an encoder column does not increase.
  HelixGeometry(const acquisition::Scan& scan, double spindle_rpm);

  [[nodiscard]] double TimeAt(std::size_t i) const {
    return t_s_ != nullptr ? (*t_s_)[i] - (*t_s_)[0] : static_cast<double>(i) * sample_period_s_;
  }
  [[nodiscard]] double PhaseAt(std::size_t i) const {
    return unwrapped_deg_.empty() ? start_phase_deg_ + 6.0 * rpm_ * TimeAt(i) : unwrapped_deg_[i];
  }
  [[nodiscard]] double AxialAt(std::size_t i) const {
    return y_mm_ != nullptr ? (*y_mm_)[i] : start_y_mm_ + feed_mm_per_min_ * TimeAt(i) / 60.0;
  }
  // True when the phase and axial position follow from the scan's settings alone (no time, axial
  // or encoder column): both are then linear in the sample index.
  [[nodiscard]] bool from_settings() const {
    return t_s_ == nullptr && y_mm_ == nullptr && unwrapped_deg_.empty();
  }
  // PhaseAt and AxialAt at a fractional sample index, by the same arithmetic (from_settings() only).
  [[nodiscard]] double PhaseAtIndex(double index) const {
    return start_phase_deg_ + 6.0 * rpm_ * (index * sample_period_s_);
  }
  [[nodiscard]] double AxialAtIndex(double index) const {
    return start_y_mm_ + feed_mm_per_min_ * (index * sample_period_s_) / 60.0;
  }
  // Axial position where the helix passes unwrapped phase u (linear between samples).
  [[nodiscard]] double AxialAtPhase(double u_deg) const;
  // Mean advance per turn (mm); negative if the wheel moves towards -y.
  [[nodiscard]] double PitchMm() const { return pitch_mm_; }
  [[nodiscard]] double rpm() const { return rpm_; }
  [[nodiscard]] bool has_encoder() const { return !unwrapped_deg_.empty(); }
  [[nodiscard]] std::size_t size() const { return size_; }

 private:
  std::size_t size_ = 0;
  const std::vector<double>* t_s_ = nullptr;
  const std::vector<double>* y_mm_ = nullptr;
  std::vector<double> unwrapped_deg_;
  double sample_period_s_ = 0.0;
  double start_phase_deg_ = 0.0;
  double start_y_mm_ = 0.0;
  double feed_mm_per_min_ = 0.0;
  double rpm_ = 0.0;
  double pitch_mm_ = 0.0;
};

}  // namespace arcwheel::processing
