#pragma once
// Test and benchmark fixture: an OUTDIR (summary.json and wheel_map.h5) written by the real writer,
// fitting::WriteProcessOutputs, for a wheel whose every section is an exact circle arc with known
// parameters, so that tests know the answers independently of the report code and read the shape
// that `arcwheel process` writes.
//
// The wheel: phase nodes c_i = i * 360 / n_phase deg, axial nodes y_j = 20 * j / (n_y - 1) mm,
//   Ra(c) = 75 + 0.003 sin(2c) mm, a(c) = 10 + 0.002 cos(c) mm, b(c) = 25 + 0.001 sin(c) mm,
//   rho(c, y) = b(c) + sqrt(Ra(c)^2 - (y - a(c))^2) + radial_offset_um / 1000,
// with cells of no valid sample (rho NaN, sample_count 0) where 90 <= c < 100 and y < 1, and
// despiked samples in the cells where 180 <= c < 190 and 5 <= y < 6.
// Processing parameters recorded: phases = n_phase, band_half_width_mm = 8,
// despike_window_half_width = 5, despike_threshold_um = 5, fit_span = "band".
//
// With `with_model` (as `arcwheel process` writes by default) the files carry a wheel model
// (summary.json "model", wheel_map.h5 /model) of known values:
//   Ra(c), a(c), b(c) as above with 1-sigma 0.2, 0.1 and 0.15 um;
//   p(u) = 0.42 cos(pi u / 8) um on u = -8, -7.9, ..., 8 mm, 1-sigma 0.02 um;
//   residual (c, y) = 0.1 sin(3c) cos(y / 1 mm) um inside the band [2, 18] mm where the cell has
//   samples, NaN elsewhere;
// and the numbers listed in FixtureModel() (report_fixture.cc).

#include <cstddef>
#include <filesystem>
#include <nlohmann/json.hpp>

namespace arcwheel::reports::testing {

struct FixtureOptions {
  std::size_t n_phase = 72;
  std::size_t n_y = 201;
  // Added to every rho, so that each section sits this far outside its recorded circle.
  double radial_offset_um = 0.0;
  // Write a wheel model, as `process` does unless given --no-model.
  bool with_model = true;
};

// The fixture wheel's circle parameters at phase c (deg).
double FixtureArcRadius_mm(double phase_deg);
double FixtureCenterAxial_mm(double phase_deg);
double FixtureCenterRadial_mm(double phase_deg);
// The fixture model's residual map value at (c, y), um (NaN where it has none).
double FixtureModelResidual_um(double phase_deg, double y_mm, bool has_samples);

// The summary.json document the writer makes for the fixture. Headline numbers are fixed literals
// (documented in the .cc) so that tests can expect their printed form.
[[nodiscard]] nlohmann::json FixtureSummary(const FixtureOptions& options);

// Writes OUTDIR/wheel_map.h5 and then OUTDIR/summary.json from `summary` (a FixtureSummary that a
// test changed), or both as the writer makes them.
void WriteFixture(const std::filesystem::path& outdir, const FixtureOptions& options,
                  const nlohmann::json& summary);
void WriteFixture(const std::filesystem::path& outdir, const FixtureOptions& options = {});

}  // namespace arcwheel::reports::testing
