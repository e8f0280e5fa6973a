#pragma once
// The report stage's reader of what `arcwheel process` writes: OUTDIR/summary.json and
// OUTDIR/wheel_map.h5, as docs/outputs.md and spec/formats.md section 3 describe them.
//
// The report is drawn from these two files alone. Every key and dataset the report uses is
// checked: a missing file, key or dataset, a value of the wrong type, or arrays of different
// lengths throw Error{kBadInput} (Error{kIo} for a file that cannot be opened) whose message
// names the file and the key or dataset. Numbers that `process` could not compute are `null` in
// JSON and NaN in HDF5; both are read as NaN.

#include <cstdint>
#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

namespace arcwheel::reports {

// summary.json "input": provenance of the scan.
struct InputProvenance {
  std::string path;
  std::string sha256;
  std::string format;  // "hdf5", "csv", or "" when not recorded
  std::int64_t samples = 0;
  std::int64_t valid_samples = 0;
  std::int64_t despiked_samples = 0;
};

// summary.json "phases": one entry per phase node, all arrays of equal length.
struct PhaseSeries {
  std::vector<double> phase_deg;
  std::vector<double> arc_radius_mm;
  std::vector<double> arc_radius_sigma_mm;
  std::vector<double> center_axial_mm;
  std::vector<double> center_radial_mm;
  std::vector<double> arc_error_um;
  // Optional in the file; empty when absent.
  std::vector<double> center_axial_sigma_mm;
  std::vector<double> center_radial_sigma_mm;
  std::vector<double> points_in_band;
  // Optional in the file; all true when absent.
  std::vector<bool> usable;
};

// summary.json "axial": one entry per axial node in the band.
struct AxialSeries {
  std::vector<double> y_mm;
  std::vector<double> runout_um;
  std::vector<double> roundness_um;
};

// One radius harmonic of the wheel model: amplitude_um * cos(order * c + phase_deg), with 1-sigma.
struct ModelHarmonic {
  int order = 0;
  double amplitude_um = 0.0;
  double amplitude_sigma_um = 0.0;
  double phase_deg = 0.0;
  double phase_sigma_deg = 0.0;
};

// summary.json "model": the wheel model's numbers (docs/wheel_model.md). Optional in the file:
// absent in schema 1.0 files, with --no-model, or when the model could not be fitted.
struct ModelSummary {
  int radius_knots = 0;         // knots per turn of Ra(c); 1 = constant
  int axial_knots = 0;          // of a(c)
  int runout_knots = 0;         // of b(c)
  std::string knots_chosen_by;  // "bic" or "given"
  double residual_rms_um = 0.0;
  double noise_sigma_um = 0.0;
  double mean_arc_radius_mm = 0.0;
  double mean_arc_radius_sigma_mm = 0.0;
  double arc_radius_range_mm = 0.0;
  double arc_radius_range_sigma_mm = 0.0;
  double variation_chi2 = 0.0;
  int variation_dof = 0;
  double variation_p_value = 0.0;
  double significance_level = 0.0;
  bool variation_significant = false;
  double profile_pv_um = 0.0;
  std::vector<ModelHarmonic> radius_harmonics;
};

struct Summary {
  std::string arcwheel_version;
  // "schema_version" as recorded; "" in files written before versions were recorded.
  std::string schema_version;
  InputProvenance input;
  double spindle_rpm_nominal = 0.0;
  double spindle_rpm_estimated = 0.0;
  double mean_arc_radius_mm = 0.0;
  double mean_arc_radius_sigma_mm = 0.0;
  double arc_radius_range_mm = 0.0;
  double arc_radius_fluctuation_pct = 0.0;
  double mean_center_axial_mm = 0.0;
  double center_axial_deviation_mm = 0.0;
  double band_half_width_mm = 0.0;
  double max_arc_error_um = 0.0;
  double max_runout_um = 0.0;
  double max_roundness_um = 0.0;
  // "band_mm" [low, high] when recorded; else mean_center_axial_mm -/+ band_half_width_mm.
  double band_low_mm = 0.0;
  double band_high_mm = 0.0;
  PhaseSeries phases;
  AxialSeries axial;
  // "scan" (wheel id, sensor, feed, sample period, ...): an object, empty when not recorded.
  nlohmann::json scan = nlohmann::json::object();
  // "processing": every processing parameter as used. Required: the report states how its
  // numbers were made.
  nlohmann::json processing = nlohmann::json::object();
  std::vector<std::string> warnings;
  // Optional extensions shown in the report when present (NaN when absent).
  double noise_sigma_um = 0.0;
  double map_sigma_um = 0.0;
  std::string spindle_rpm_source;
  double mean_center_axial_sigma_mm = 0.0;  // NaN when absent
  // Phase-to-phase spread of the per-phase arc radii, and the parts of it that the per-phase
  // noise explains and that remain (in quadrature); NaN when absent.
  double arc_radius_std_mm = 0.0;
  double arc_radius_noise_std_mm = 0.0;
  double arc_radius_excess_std_mm = 0.0;
  // What runout includes (wheel plus spindle error motion); "" when absent.
  std::string runout_note;
  // "model" when the file has one.
  std::optional<ModelSummary> model;
  // "uncertainty" (schema 1.2): per headline key, the estimate a decision uses and its U, k and
  // u_c (NaN where null); empty when the file has none.
  struct QuantityUncertainty {
    double value = 0.0, expanded = 0.0, coverage_factor = 0.0, standard_uncertainty = 0.0;
    // The type A part alone (from the data): what a comparison of two scans of one sensor uses,
    // whose type B parts are the same in both.
    double type_a_uncertainty = 0.0;
  };
  std::map<std::string, QuantityUncertainty> uncertainty;
  double coverage_probability = 0.95;
  // "characteristics" (formats.md 3.3): per headline key (the characteristic's name and its
  // value's unit, "max_roundness_um"), the value under its operator, U, k, the operator in short,
  // where, and the decision process made ("" without a tolerance); empty when the file has none.
  struct Characteristic {
    double value = 0.0, expanded = 0.0, coverage_factor = 0.0;
    std::string operator_text, where, decision, rule;
    // The operator's closed-profile cut-off (UPR) and association, and the axial node of the
    // largest value ("at_y_mm"), for the polar plot of the worst section.
    std::optional<double> cutoff_upr;
    std::string association;
    std::optional<double> at_y_mm;
  };
  std::map<std::string, Characteristic> characteristics;
};

// wheel_map.h5 "/model": the wheel model's functions. Ra(c), a(c), b(c) and their 1-sigma on the
// map's phase nodes; p(u) on its own nodes; the residual map on the map's grid (empty when the
// file has none).
struct ModelCurves {
  std::vector<double> arc_radius_mm, arc_radius_sigma_mm;
  std::vector<double> center_axial_mm, center_axial_sigma_mm;
  std::vector<double> center_radial_mm, center_radial_sigma_mm;
  std::vector<double> profile_u_mm, profile_error_um, profile_error_sigma_um;
  std::vector<double> residual_um;  // [n_phase, n_y], NaN where a cell holds no sample
};

// wheel_map.h5: the regular map rho(c, y) and its diagnostics. Grids are row-major
// [n_phase, n_y]: value (i_phase, i_y) is at index i_phase * n_y + i_y.
struct WheelMapData {
  std::vector<double> phase_deg;       // /map/phase_deg
  std::vector<double> y_mm;            // /map/y_mm
  std::vector<double> rho_mm;          // /map/rho
  std::vector<double> form_error_um;   // /map/form_error_um
  std::vector<double> sample_count;    // /map/sample_count
  std::vector<double> despiked_count;  // /map/despiked_count
  std::optional<ModelCurves> model;    // /model, when the file has it
  // Root attributes, empty when absent.
  std::string arcwheel_version;
  std::string input_sha256;
  [[nodiscard]] std::size_t n_phase() const { return phase_deg.size(); }
  [[nodiscard]] std::size_t n_y() const { return y_mm.size(); }
};

// Parses summary.json. Throws Error{kIo} if it cannot be read, Error{kBadInput} naming the file
// and the key for invalid JSON, a missing contract key, a wrong type or unequal array lengths.
[[nodiscard]] Summary ReadSummary(const std::filesystem::path& path);
// Same from a string; `name` stands for the file in messages.
[[nodiscard]] Summary ParseSummary(const std::string& text, const std::string& name);

// Reads wheel_map.h5. Throws Error{kIo} for a missing file, Error{kBadInput} naming the file and
// dataset for a missing dataset or one whose shape does not match the phase and axial nodes.
[[nodiscard]] WheelMapData ReadWheelMap(const std::filesystem::path& path);

// Both inputs of a report, checked against each other.
struct ReportInputs {
  Summary summary;
  WheelMapData map;
  std::filesystem::path summary_path;
  std::filesystem::path map_path;
};

// Reads OUTDIR/summary.json and OUTDIR/wheel_map.h5 and checks that they describe the same scan
// (same input SHA-256 when the map records one, same number of phases) and that the map holds
// /model when the summary holds "model" (a map's /model without one in the summary is ignored).
// Throws as above.
[[nodiscard]] ReportInputs ReadReportInputs(const std::filesystem::path& outdir);

}  // namespace arcwheel::reports
