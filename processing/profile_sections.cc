#include "processing/profile_sections.h"

#include <fmt/core.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <numeric>
#include <vector>

#include "core/error.h"
#include "core/nan.h"
#include "processing/helix_geometry.h"

namespace arcwheel::processing {
namespace {

constexpr const char* kProfileSectionsStage = "processing.profile";
constexpr double kDefaultAxialStepMm = 0.1;

// Sums of each (phase node, column) cell over the frames nearest the node.
struct CellSums {
  std::vector<double> sum, sum2;
  std::vector<int> count;
  std::vector<int> frames;  // per node
};

CellSums SumFrames(const acquisition::ProfileScan& scan, int phases) {
  const std::size_t points = scan.points();
  const double step = 360.0 / phases;
  CellSums s;
  s.sum.assign(static_cast<std::size_t>(phases) * points, 0.0);
  s.sum2.assign(s.sum.size(), 0.0);
  s.count.assign(s.sum.size(), 0);
  s.frames.assign(static_cast<std::size_t>(phases), 0);
  for (std::size_t f = 0; f < scan.frames(); ++f) {
    const auto node = static_cast<std::size_t>(RoundHalfAway(PhaseInTurn(scan.PhaseDeg(f)) / step) % phases);
    ++s.frames[node];
    const double* z = scan.z_mm.data() + f * points;
    double* sum = s.sum.data() + node * points;
    double* sum2 = s.sum2.data() + node * points;
    int* count = s.count.data() + node * points;
    for (std::size_t k = 0; k < points; ++k) {
      if (!std::isfinite(z[k])) continue;
      sum[k] += z[k];
      sum2[k] += z[k] * z[k];
      ++count[k];
    }
  }
  return s;
}

// The pooled within-cell spread of the readings.
double PooledSpread(const CellSums& s) {
  double ss = 0.0, dof = 0.0;
  for (std::size_t i = 0; i < s.sum.size(); ++i) {
    if (s.count[i] < 2) continue;
    ss += std::max(0.0, s.sum2[i] - s.sum[i] * s.sum[i] / s.count[i]);
    dof += s.count[i] - 1;
  }
  return dof > 0 ? std::sqrt(ss / dof) : 0.0;
}

Section MakeSection(const acquisition::ProfileScan& scan, const CellSums& s, std::size_t node,
                    double spread) {
  const std::size_t points = scan.points();
  const acquisition::ProfilePlacement& p = scan.placement;
  const double tilt = p.tilt_deg * std::numbers::pi / 180.0;
  const double c = std::cos(tilt), sn = std::sin(tilt);
  Section section;
  for (std::size_t k = 0; k < points; ++k) {
    const std::size_t i = node * points + k;
    if (s.count[i] == 0) continue;
    const double r = scan.metadata.radius_sign * s.sum[i] / s.count[i];
    const double x = scan.x_mm[k];
    section.y_mm.push_back(p.axial_offset_mm + x * c - r * sn);
    section.rho_mm.push_back(x * sn + r * c);
    section.sigma_mm.push_back(spread / std::sqrt(static_cast<double>(s.count[i])));
  }
  // The fits and the map read a section in axial order; a sensor mounted with X towards -y gives
  // its columns in the opposite order.
  std::vector<std::size_t> order(section.y_mm.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(),
                   [&](std::size_t a, std::size_t b) { return section.y_mm[a] < section.y_mm[b]; });
  Section sorted;
  for (const std::size_t k : order) {
    sorted.y_mm.push_back(section.y_mm[k]);
    sorted.rho_mm.push_back(section.rho_mm[k]);
    sorted.sigma_mm.push_back(section.sigma_mm[k]);
  }
  return sorted;
}

// rho of a section at y, linear between its neighbouring points; NaN outside them.
double Interpolate(const Section& section, double y) {
  const auto it = std::lower_bound(section.y_mm.begin(), section.y_mm.end(), y);
  if (it == section.y_mm.end()) return kNaN;
  const auto k = static_cast<std::size_t>(it - section.y_mm.begin());
  if (section.y_mm[k] == y) return section.rho_mm[k];
  if (k == 0) return kNaN;
  const double w = (y - section.y_mm[k - 1]) / (section.y_mm[k] - section.y_mm[k - 1]);
  return section.rho_mm[k - 1] + w * (section.rho_mm[k] - section.rho_mm[k - 1]);
}

void LayOutMap(const acquisition::ProfileScan& scan, const MapOptions& options, const CellSums& s,
               WheelMap& map) {
  double low = -std::numeric_limits<double>::infinity(), high = std::numeric_limits<double>::infinity();
  for (const Section& section : map.sections) {
    low = std::max(low, section.y_mm.front());
    high = std::min(high, section.y_mm.back());
  }
  if (!(high > low)) {
    throw Error(ErrorCode::kBadInput, kProfileSectionsStage,
                fmt::format("'{}': the phases' sections share no axial span", scan.path));
  }
  const double step = options.axial_step_mm > 0 ? options.axial_step_mm : kDefaultAxialStepMm;
  map.axial_step_mm = step;
  for (double m = std::ceil(low / step); m * step <= high; m += 1.0) map.y_mm.push_back(m * step);
  const std::size_t n_y = map.n_y(), points = scan.points();
  map.rho_mm.assign(map.n_phase() * n_y, kNaN);
  map.sample_count.assign(map.n_phase() * n_y, 0);
  map.despiked_count.assign(map.n_phase() * n_y, 0);
  // Each node's readings count is that of the column nearest it (without tilt, the column whose X
  // is nearest).
  std::vector<std::size_t> nearest(n_y);
  for (std::size_t m = 0; m < n_y; ++m) {
    const double x = map.y_mm[m] - scan.placement.axial_offset_mm;
    const auto it = std::min_element(scan.x_mm.begin(), scan.x_mm.end(),
                                     [&](double a, double b) { return std::abs(a - x) < std::abs(b - x); });
    nearest[m] = static_cast<std::size_t>(it - scan.x_mm.begin());
  }
  for (std::size_t j = 0; j < map.n_phase(); ++j) {
    for (std::size_t m = 0; m < n_y; ++m) {
      map.rho_mm[j * n_y + m] = Interpolate(map.sections[j], map.y_mm[m]);
      map.sample_count[j * n_y + m] = s.count[j * points + nearest[m]];
    }
  }
}

}  // namespace

ProfileSectionsResult BuildProfileSections(const acquisition::ProfileScan& scan, const MapOptions& options) {
  ThrowIfProblems(ErrorCode::kInvalidOption, kProfileSectionsStage, options.Problems());
  const CellSums sums = SumFrames(scan, options.phases);
  ProfileSectionsResult out;
  out.point_spread_mm = PooledSpread(sums);
  out.min_frames_per_phase = *std::min_element(sums.frames.begin(), sums.frames.end());
  for (const int c : sums.count) out.valid_points += static_cast<std::size_t>(c);
  WheelMap& map = out.map;
  const double step = 360.0 / options.phases;
  for (int j = 0; j < options.phases; ++j) {
    const auto node = static_cast<std::size_t>(j);
    if (sums.frames[node] == 0) {
      throw Error(
          ErrorCode::kBadInput, kProfileSectionsStage,
          fmt::format("'{}': no frame lies nearest the phase node {} deg ({} frames for {} phases; scan more "
                      "frames a turn or give fewer --phases)",
                      scan.path, j * step, scan.frames(), options.phases));
    }
    map.phase_deg.push_back(j * step);
    map.sections.push_back(MakeSection(scan, sums, node, out.point_spread_mm));
  }
  map.noise_sigma_mm = out.point_spread_mm;
  LayOutMap(scan, options, sums, map);
  return out;
}

}  // namespace arcwheel::processing
