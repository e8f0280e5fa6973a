#pragma once
// The arc-profile (toroidal) wheel as the toolpath sees it, and reading it from a `summary.json`
// written by `arcwheel process` (keys of docs/outputs.md).
//
// Geometry (method.md A.7, A.8): the wheel turns about an axis parallel to the machine's Y. Its rim
// is a torus: an arc of radius Ra (the arc radius) whose centre runs on a circle of radius
// Rb = total radius - Ra (the base radius) about the wheel centre, in the plane y = wheel-centre y.

#include <filesystem>
#include <limits>
#include <string>
#include <vector>

namespace arcwheel::grinding {

struct Wheel {
  double arc_radius_mm = 0.0;   // Ra > 0
  double base_radius_mm = 0.0;  // Rb = total radius - Ra, >= 0
  // Half of the usable axial width of the arc about its centre: a contact farther than this
  // from the arc centre (along the wheel axis) is out of the wheel's reach.
  double half_width_mm = 0.0;
  // Optional measured mean profile: deviation of the real arc from the circle of radius Ra, along
  // the arc's normal (positive = material outside the circle), at axial positions u relative to
  // the arc centre. Empty: the ideal circle. When present, the reach is limited to its u range.
  std::vector<double> profile_u_mm{};
  std::vector<double> profile_error_um{};
  std::string description{};  // for file headers

  [[nodiscard]] double TotalRadius() const { return arc_radius_mm + base_radius_mm; }
  [[nodiscard]] bool HasProfile() const { return !profile_u_mm.empty(); }
  // Effective arc radius for a contact at axial offset u (mm) from the arc centre: Ra plus the
  // profile error there (linear interpolation), or Ra without a profile. Precondition: Reaches(u).
  [[nodiscard]] double ArcRadiusAt(double u_mm) const;
  // True if a contact at axial offset u lies on the usable arc.
  [[nodiscard]] bool Reaches(double u_mm) const;
  // Empty when valid, else one line per violation (Ceres IsValid style).
  [[nodiscard]] std::vector<std::string> Problems() const;
};

// What the toolpath and the prediction need from a `summary.json`.
struct WheelSummary {
  double mean_arc_radius_mm = 0.0;
  double mean_arc_radius_sigma_mm = 0.0;
  double wheel_diameter_mm = 0.0;  // 0 when `scan.wheel_diameter_mm` is null or missing
  double max_runout_um = 0.0;
  std::vector<double> profile_u_mm;      // `mean_profile.u_mm` (may be empty)
  std::vector<double> profile_error_um;  // `mean_profile.error_um`
  // Per-phase arrays of `phases`, usable phases only (all phases if `usable` is absent).
  std::vector<double> phase_deg;
  std::vector<double> arc_radius_mm;
  std::vector<double> center_radial_mm;
  std::string wheel_id;
  std::string arcwheel_version;
  // The wheel model's mean arc radius and its 1-sigma (`model.mean_arc_radius_mm`, `_sigma_mm`);
  // NaN when the summary has no model.
  double model_mean_arc_radius_mm = std::numeric_limits<double>::quiet_NaN();
  double model_mean_arc_radius_sigma_mm = std::numeric_limits<double>::quiet_NaN();
};

// The wheel model's profile error common to all phases, p(u): radial deviation from the arc (um,
// positive = rim standing out) at axial offsets u from the arc centre (mm), finite nodes only.
struct ProfileError {
  std::vector<double> u_mm;
  std::vector<double> error_um;
};

// Reads p(u) from a wheel_map.h5's /model/profile_u_mm and /model/profile_error_um. Throws
// Error{kBadInput, "grinding.wheel"} naming the file and the dataset if it has no model (processed
// with --no-model) or fewer than 2 finite nodes, Error{kIo} if it cannot be read.
[[nodiscard]] ProfileError ReadModelProfile(const std::filesystem::path& wheel_map);

// Reads a summary.json. Throws Error{kIo} if it cannot be read, Error{kBadInput,
// "grinding.wheel"} naming the file and key if a required key is missing or malformed.
[[nodiscard]] WheelSummary ReadWheelSummary(const std::filesystem::path& path);

}  // namespace arcwheel::grinding
