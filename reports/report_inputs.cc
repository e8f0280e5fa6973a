#include "reports/report_inputs.h"

#include <fmt/format.h>

#include <cmath>
#include <fstream>
#include <limits>
#include <sstream>

#include "core/error.h"
#include "core/hdf5.h"
#include "core/json_text.h"

namespace arcwheel::reports {
namespace {

using nlohmann::json;
constexpr const char* kSummaryStage = "reports.summary";
constexpr const char* kMapStage = "reports.wheel_map";
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// Locates a value in summary.json for error messages: "'OUTDIR/summary.json' key 'phases.y_mm'".
struct JsonWhere {
  const std::string& file;
  std::string key;
  [[nodiscard]] std::string Describe() const { return "'" + file + "' key '" + key + "'"; }
  [[nodiscard]] JsonWhere Child(const std::string& name) const {
    return {file, key.empty() ? name : key + "." + name};
  }
};

[[noreturn]] void BadSummary(const JsonWhere& where, const std::string& problem) {
  throw Error(ErrorCode::kBadInput, kSummaryStage, where.Describe() + " " + problem);
}

const json& RequireKey(const json& object, const JsonWhere& parent, const std::string& name) {
  const auto it = object.find(name);
  if (it == object.end()) BadSummary(parent.Child(name), "is missing");
  return *it;
}

const json& RequireObject(const json& object, const JsonWhere& parent, const std::string& name) {
  const json& value = RequireKey(object, parent, name);
  if (!value.is_object()) BadSummary(parent.Child(name), "is not a JSON object");
  return value;
}

// A number, or null for "could not be computed" (read as NaN).
double NumberOrNull(const json& value, const JsonWhere& where) {
  if (value.is_null()) return kNaN;
  if (!value.is_number()) BadSummary(where, "is not a number (found " + value.dump() + ")");
  return value.get<double>();
}

double RequireNumber(const json& object, const JsonWhere& parent, const std::string& name) {
  return NumberOrNull(RequireKey(object, parent, name), parent.Child(name));
}

double OptionalNumber(const json& object, const JsonWhere& parent, const std::string& name) {
  const auto it = object.find(name);
  return it == object.end() ? kNaN : NumberOrNull(*it, parent.Child(name));
}

std::int64_t RequireCount(const json& object, const JsonWhere& parent, const std::string& name) {
  const json& value = RequireKey(object, parent, name);
  if (!value.is_number_integer() || value.get<std::int64_t>() < 0) {
    BadSummary(parent.Child(name), "is not a non-negative integer (found " + value.dump() + ")");
  }
  return value.get<std::int64_t>();
}

std::string RequireString(const json& object, const JsonWhere& parent, const std::string& name) {
  const json& value = RequireKey(object, parent, name);
  if (!value.is_string()) BadSummary(parent.Child(name), "is not a string (found " + value.dump() + ")");
  return value.get<std::string>();
}

std::string OptionalString(const json& object, const JsonWhere& parent, const std::string& name) {
  const auto it = object.find(name);
  if (it == object.end() || it->is_null()) return "";
  if (!it->is_string()) BadSummary(parent.Child(name), "is not a string (found " + it->dump() + ")");
  return it->get<std::string>();
}

std::vector<double> RequireNumberArray(const json& object, const JsonWhere& parent, const std::string& name,
                                       std::size_t expected_size) {
  const json& value = RequireKey(object, parent, name);
  const JsonWhere where = parent.Child(name);
  if (!value.is_array()) BadSummary(where, "is not an array");
  if (expected_size != std::string::npos && value.size() != expected_size) {
    BadSummary(where, fmt::format("has {} entries, expected {} (as many as its siblings)", value.size(),
                                  expected_size));
  }
  std::vector<double> numbers;
  numbers.reserve(value.size());
  for (std::size_t i = 0; i < value.size(); ++i) {
    numbers.push_back(NumberOrNull(value[i], where.Child(std::to_string(i))));
  }
  return numbers;
}

InputProvenance ParseInput(const json& root, const JsonWhere& top) {
  const JsonWhere where = top.Child("input");
  const json& input = RequireObject(root, top, "input");
  InputProvenance provenance;
  provenance.path = RequireString(input, where, "path");
  provenance.sha256 = RequireString(input, where, "sha256");
  provenance.format = OptionalString(input, where, "format");
  provenance.samples = RequireCount(input, where, "samples");
  provenance.valid_samples = RequireCount(input, where, "valid_samples");
  provenance.despiked_samples = RequireCount(input, where, "despiked_samples");
  return provenance;
}

PhaseSeries ParsePhases(const json& root, const JsonWhere& top) {
  const JsonWhere where = top.Child("phases");
  const json& phases = RequireObject(root, top, "phases");
  PhaseSeries series;
  series.phase_deg = RequireNumberArray(phases, where, "phase_deg", std::string::npos);
  const std::size_t n = series.phase_deg.size();
  if (n == 0) BadSummary(where.Child("phase_deg"), "is empty");
  series.arc_radius_mm = RequireNumberArray(phases, where, "arc_radius_mm", n);
  series.arc_radius_sigma_mm = RequireNumberArray(phases, where, "arc_radius_sigma_mm", n);
  series.center_axial_mm = RequireNumberArray(phases, where, "center_axial_mm", n);
  series.center_radial_mm = RequireNumberArray(phases, where, "center_radial_mm", n);
  series.arc_error_um = RequireNumberArray(phases, where, "arc_error_um", n);
  series.usable.assign(n, true);
  if (const auto it = phases.find("usable"); it != phases.end()) {
    const JsonWhere usable_where = where.Child("usable");
    if (!it->is_array() || it->size() != n)
      BadSummary(usable_where, fmt::format("is not an array of {} booleans", n));
    for (std::size_t i = 0; i < n; ++i) {
      if (!(*it)[i].is_boolean()) BadSummary(usable_where.Child(std::to_string(i)), "is not a boolean");
      series.usable[i] = (*it)[i].get<bool>();
    }
  }
  return series;
}

AxialSeries ParseAxial(const json& root, const JsonWhere& top) {
  const JsonWhere where = top.Child("axial");
  const json& axial = RequireObject(root, top, "axial");
  AxialSeries series;
  series.y_mm = RequireNumberArray(axial, where, "y_mm", std::string::npos);
  series.runout_um = RequireNumberArray(axial, where, "runout_um", series.y_mm.size());
  series.roundness_um = RequireNumberArray(axial, where, "roundness_um", series.y_mm.size());
  return series;
}

void ParseBand(const json& root, const JsonWhere& top, Summary& summary) {
  summary.band_low_mm = summary.mean_center_axial_mm - summary.band_half_width_mm;
  summary.band_high_mm = summary.mean_center_axial_mm + summary.band_half_width_mm;
  const auto it = root.find("band_mm");
  if (it == root.end() || it->is_null()) return;
  const std::vector<double> band = RequireNumberArray(root, top, "band_mm", 2);
  summary.band_low_mm = band[0];
  summary.band_high_mm = band[1];
}

std::vector<std::string> ParseWarnings(const json& root, const JsonWhere& top) {
  std::vector<std::string> warnings;
  const auto it = root.find("warnings");
  if (it == root.end() || it->is_null()) return warnings;
  const JsonWhere where = top.Child("warnings");
  if (!it->is_array()) BadSummary(where, "is not an array of strings");
  for (std::size_t i = 0; i < it->size(); ++i) {
    if (!(*it)[i].is_string()) BadSummary(where.Child(std::to_string(i)), "is not a string");
    warnings.push_back((*it)[i].get<std::string>());
  }
  return warnings;
}

void ParseHeadline(const json& root, const JsonWhere& top, Summary& summary) {
  summary.spindle_rpm_nominal = RequireNumber(root, top, "spindle_rpm_nominal");
  summary.spindle_rpm_estimated = RequireNumber(root, top, "spindle_rpm_estimated");
  summary.mean_arc_radius_mm = RequireNumber(root, top, "mean_arc_radius_mm");
  summary.mean_arc_radius_sigma_mm = RequireNumber(root, top, "mean_arc_radius_sigma_mm");
  summary.arc_radius_range_mm = RequireNumber(root, top, "arc_radius_range_mm");
  summary.arc_radius_fluctuation_pct = RequireNumber(root, top, "arc_radius_fluctuation_pct");
  summary.mean_center_axial_mm = RequireNumber(root, top, "mean_center_axial_mm");
  summary.center_axial_deviation_mm = RequireNumber(root, top, "center_axial_deviation_mm");
  summary.band_half_width_mm = RequireNumber(root, top, "band_half_width_mm");
  summary.max_arc_error_um = RequireNumber(root, top, "max_arc_error_um");
  summary.max_runout_um = RequireNumber(root, top, "max_runout_um");
  summary.max_roundness_um = RequireNumber(root, top, "max_roundness_um");
  summary.noise_sigma_um = OptionalNumber(root, top, "noise_sigma_um");
  summary.map_sigma_um = OptionalNumber(root, top, "map_sigma_um");
  summary.spindle_rpm_source = OptionalString(root, top, "spindle_rpm_source");
}

std::string ReadWholeFile(const std::filesystem::path& path, const char* stage) {
  std::ifstream stream(path, std::ios::binary);
  if (!stream) throw Error(ErrorCode::kIo, stage, "cannot open '" + path.string() + "'");
  std::ostringstream contents;
  contents << stream.rdbuf();
  if (stream.bad()) throw Error(ErrorCode::kIo, stage, "cannot read '" + path.string() + "'");
  return contents.str();
}

[[noreturn]] void BadMap(const std::filesystem::path& path, const std::string& dataset,
                         const std::string& problem) {
  throw Error(ErrorCode::kBadInput, kMapStage,
              "'" + path.string() + "' dataset '" + dataset + "' " + problem);
}

std::vector<double> ReadDataset(const hdf5::File& file, const std::string& dataset,
                                const std::vector<hsize_t>& expected_shape) {
  if (!file.HasObject(dataset)) BadMap(file.path(), dataset, "is missing");
  const std::vector<hsize_t> shape = file.Shape(dataset);
  if (shape != expected_shape) {
    auto text = [](const std::vector<hsize_t>& dims) { return fmt::format("[{}]", fmt::join(dims, ", ")); };
    BadMap(file.path(), dataset, "has shape " + text(shape) + ", expected " + text(expected_shape));
  }
  return file.ReadDoubles(dataset);
}

std::vector<double> ReadAxisDataset(const hdf5::File& file, const std::string& dataset) {
  if (!file.HasObject(dataset)) BadMap(file.path(), dataset, "is missing");
  const std::vector<hsize_t> shape = file.Shape(dataset);
  if (shape.size() != 1 || shape[0] < 2)
    BadMap(file.path(), dataset, "is not a 1-D array of at least 2 nodes");
  std::vector<double> nodes = file.ReadDoubles(dataset);
  for (std::size_t i = 1; i < nodes.size(); ++i) {
    if (!(nodes[i] > nodes[i - 1])) {
      BadMap(file.path(), dataset,
             fmt::format("is not strictly increasing at index {} ({} after {})", i, nodes[i], nodes[i - 1]));
    }
  }
  return nodes;
}

}  // namespace

Summary ParseSummary(const std::string& text, const std::string& name) {
  const json root = ParseJsonText(text, name, kSummaryStage);
  const JsonWhere top{name, ""};
  if (!root.is_object())
    throw Error(ErrorCode::kBadInput, kSummaryStage, "'" + name + "' is not a JSON object");
  Summary summary;
  summary.arcwheel_version = RequireString(root, top, "arcwheel_version");
  summary.input = ParseInput(root, top);
  ParseHeadline(root, top, summary);
  ParseBand(root, top, summary);
  summary.phases = ParsePhases(root, top);
  summary.axial = ParseAxial(root, top);
  summary.processing = RequireObject(root, top, "processing");
  if (const auto it = root.find("scan"); it != root.end() && !it->is_null()) {
    if (!it->is_object()) BadSummary(top.Child("scan"), "is not a JSON object");
    summary.scan = *it;
  }
  summary.warnings = ParseWarnings(root, top);
  return summary;
}

Summary ReadSummary(const std::filesystem::path& path) {
  if (!std::filesystem::exists(path)) {
    throw Error(ErrorCode::kIo, kSummaryStage,
                "'" + path.string() + "' does not exist (run `arcwheel process` first)");
  }
  return ParseSummary(ReadWholeFile(path, kSummaryStage), path.string());
}

WheelMapData ReadWheelMap(const std::filesystem::path& path) {
  if (!std::filesystem::exists(path)) {
    throw Error(ErrorCode::kIo, kMapStage,
                "'" + path.string() + "' does not exist (run `arcwheel process` first)");
  }
  hdf5::ReadFirstInChildProcess(path, [&] { (void)ReadWheelMap(path); });
  const hdf5::File file = hdf5::File::OpenReadOnly(path);
  WheelMapData map;
  map.phase_deg = ReadAxisDataset(file, "/map/phase_deg");
  map.y_mm = ReadAxisDataset(file, "/map/y_mm");
  const std::vector<hsize_t> grid = {map.n_phase(), map.n_y()};
  map.rho_mm = ReadDataset(file, "/map/rho", grid);
  map.form_error_um = ReadDataset(file, "/map/form_error_um", grid);
  map.sample_count = ReadDataset(file, "/map/sample_count", grid);
  map.despiked_count = ReadDataset(file, "/map/despiked_count", grid);
  map.arcwheel_version = file.ReadAttributeString("/", "arcwheel_version").value_or("");
  map.input_sha256 = file.ReadAttributeString("/", "input_sha256").value_or("");
  return map;
}

ReportInputs ReadReportInputs(const std::filesystem::path& outdir) {
  ReportInputs inputs;
  inputs.summary_path = outdir / "summary.json";
  inputs.map_path = outdir / "wheel_map.h5";
  inputs.summary = ReadSummary(inputs.summary_path);
  inputs.map = ReadWheelMap(inputs.map_path);
  const Summary& summary = inputs.summary;
  if (!inputs.map.input_sha256.empty() && inputs.map.input_sha256 != summary.input.sha256) {
    throw Error(ErrorCode::kBadInput, kMapStage,
                "'" + inputs.map_path.string() + "' attribute 'input_sha256' (" + inputs.map.input_sha256 +
                    ") differs from '" + inputs.summary_path.string() + "' key 'input.sha256' (" +
                    summary.input.sha256 + "): the two files describe different scans");
  }
  if (inputs.map.n_phase() != summary.phases.phase_deg.size()) {
    throw Error(
        ErrorCode::kBadInput, kMapStage,
        fmt::format("'{}' dataset '/map/phase_deg' has {} phases but '{}' key 'phases.phase_deg' has {}",
                    inputs.map_path.string(), inputs.map.n_phase(), inputs.summary_path.string(),
                    summary.phases.phase_deg.size()));
  }
  for (std::size_t i = 0; i < inputs.map.n_phase(); ++i) {
    if (std::abs(inputs.map.phase_deg[i] - summary.phases.phase_deg[i]) > 1e-6) {
      throw Error(
          ErrorCode::kBadInput, kMapStage,
          fmt::format(
              "'{}' dataset '/map/phase_deg' [{}] = {} differs from '{}' key 'phases.phase_deg.{}' = {}",
              inputs.map_path.string(), i, inputs.map.phase_deg[i], inputs.summary_path.string(), i,
              summary.phases.phase_deg[i]));
    }
  }
  return inputs;
}

}  // namespace arcwheel::reports
