#pragma once
// The default type B budget of arcwheel's simulated sensor and machine (docs/uncertainty.md): a
// laser triangulation sensor of the Keyence LK-H020 class that the paper used (method.md A.1:
// range +-3 mm, accuracy 1.2 um, resolution 0.01 um), a machine Y axis that feeds the sensor
// along the wheel, and a steel-cored wheel scanned in a workshop. Each input names where its
// figure comes from; replace them with the figures of your own sensor (a budget file,
// uncertainty/budget_json.h). The simulator injects none of these errors: on simulated scans the
// type A part alone describes the error.

#include <string>
#include <vector>

#include "uncertainty/budget_json.h"

namespace arcwheel::uncertainty {

// The geometry the sensitivity coefficients depend on.
struct WheelGeometry {
  double arc_radius_mm = 55.4423;   // Ra, > 0
  double band_half_width_mm = 8.0;  // w: the band the arcs are fitted over, > 0, < Ra
  double wheel_radius_mm = 200.0;   // Rw: spindle axis to the rim's apex, > 0
  [[nodiscard]] std::vector<std::string> Problems() const;
};

struct SensorBudgetOptions {
  // Gain error of the sensor left after calibration, rectangular half-width, ppm. >= 0.
  double scale_ppm = 200.0;
  // Non-linearity over the full scale, +- um (LK-H020: 0.02 % of 6 mm = 1.2 um). >= 0.
  double linearity_um = 1.2;
  // The span the linearity is stated over, mm (LK-H020: +-3 mm). > 0.
  double full_scale_mm = 6.0;
  // Resolution (least step) of a reading, um (LK-H020: 0.01 um). >= 0.
  double resolution_um = 0.01;
  // Positioning error of the axial (Y) axis over the band, +- um (a glass-scale encoder). >= 0.
  double axial_error_um = 1.0;
  // The wheel's temperature against the 20 degC reference (ISO 1), +- K (a workshop). >= 0.
  double temperature_k = 2.0;
  // Thermal expansion coefficient of the wheel's core, 1/K (steel: 11.5e-6). >= 0.
  double expansion_per_k = 11.5e-6;
  // Lateral offset of the beam from the spindle axis left after alignment, +- mm. >= 0.
  double beam_offset_mm = 0.1;
  // Empty when valid, else "SensorBudgetOptions::scale_ppm = -1 violates >= 0".
  [[nodiscard]] std::vector<std::string> Problems() const;
};

// The sagitta of the band, w^2 / (2 Ra) (mm): the radial depth of an arc section, over which
// the sensor's readings range.
[[nodiscard]] double BandSagittaMm(const WheelGeometry& geometry);

// The default budget for `geometry` (docs/uncertainty.md lists each input and its sensitivity).
// Throws Error{kInvalidOption, "uncertainty.budget"} listing the problems of either argument.
[[nodiscard]] BudgetFile DefaultBudget(const WheelGeometry& geometry,
                                       const SensorBudgetOptions& options = {});

}  // namespace arcwheel::uncertainty
