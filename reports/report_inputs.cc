#include "reports/report_inputs.h"

#include <fmt/format.h>

#include <cmath>
#include <fstream>
#include <limits>
#include <sstream>

#include "core/error.h"
#include "core/hdf5.h"
#include "core/json_text.h"
#include "core/nan.h"
#include "schema/summary.h"
#include "schema/wheel_map.h"

namespace arcwheel::reports {
namespace {

using nlohmann::json;
namespace key = schema::summary;
namespace h5 = schema::wheel_map;
constexpr const char* kSummaryStage = "reports.summary";
constexpr const char* kMapStage = "reports.wheel_map";

// Locates a value in summary.json for error messages: "'OUTDIR/summary.json' key 'phases.y_mm'".
struct JsonWhere {
  const std::string& file;
  std::string key;
  [[nodiscard]] std::string Describe() const { return "'" + file + "' key '" + key + "'"; }
  [[nodiscard]] JsonWhere Child(std::string_view name) const {
    return {file, key.empty() ? std::string(name) : key + "." + std::string(name)};
  }
};

[[noreturn]] void BadSummary(const JsonWhere& where, const std::string& problem) {
  throw Error(ErrorCode::kBadInput, kSummaryStage, where.Describe() + " " + problem);
}

const json& RequireKey(const json& object, const JsonWhere& parent, std::string_view name) {
  const auto it = object.find(name);
  if (it == object.end()) BadSummary(parent.Child(name), "is missing");
  return *it;
}

const json& RequireObject(const json& object, const JsonWhere& parent, std::string_view name) {
  const json& value = RequireKey(object, parent, name);
  if (!value.is_object()) BadSummary(parent.Child(name), "is not a JSON object");
  return value;
}

// A number, or null for "could not be computed" (read as NaN).
double NumberOrNull(const json& value, const JsonWhere& where) {
  if (value.is_null()) return kNaN;
  if (!value.is_number()) BadSummary(where, "is not a number (found " + JsonText(value) + ")");
  return value.get<double>();
}

double RequireNumber(const json& object, const JsonWhere& parent, std::string_view name) {
  return NumberOrNull(RequireKey(object, parent, name), parent.Child(name));
}

double OptionalNumber(const json& object, const JsonWhere& parent, std::string_view name) {
  const auto it = object.find(name);
  return it == object.end() ? kNaN : NumberOrNull(*it, parent.Child(name));
}

std::int64_t RequireCount(const json& object, const JsonWhere& parent, std::string_view name) {
  const json& value = RequireKey(object, parent, name);
  if (!value.is_number_integer() || value.get<std::int64_t>() < 0) {
    BadSummary(parent.Child(name), "is not a non-negative integer (found " + JsonText(value) + ")");
  }
  return value.get<std::int64_t>();
}

int RequireInt(const json& object, const JsonWhere& parent, std::string_view name) {
  const json& value = RequireKey(object, parent, name);
  if (!value.is_number_integer() || value.get<std::int64_t>() < 0 || value.get<std::int64_t>() > 1000000) {
    BadSummary(parent.Child(name), "is not a non-negative integer (found " + JsonText(value) + ")");
  }
  return value.get<int>();
}

bool RequireBool(const json& object, const JsonWhere& parent, std::string_view name) {
  const json& value = RequireKey(object, parent, name);
  if (!value.is_boolean())
    BadSummary(parent.Child(name), "is not true or false (found " + JsonText(value) + ")");
  return value.get<bool>();
}

std::string RequireString(const json& object, const JsonWhere& parent, std::string_view name) {
  const json& value = RequireKey(object, parent, name);
  if (!value.is_string()) BadSummary(parent.Child(name), "is not a string (found " + JsonText(value) + ")");
  return value.get<std::string>();
}

std::string OptionalString(const json& object, const JsonWhere& parent, std::string_view name) {
  const auto it = object.find(name);
  if (it == object.end() || it->is_null()) return "";
  if (!it->is_string()) BadSummary(parent.Child(name), "is not a string (found " + it->dump() + ")");
  return it->get<std::string>();
}

std::vector<double> RequireNumberArray(const json& object, const JsonWhere& parent, std::string_view name,
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
  const JsonWhere where = top.Child(key::kInput);
  const json& input = RequireObject(root, top, key::kInput);
  InputProvenance provenance;
  provenance.path = RequireString(input, where, key::input::kPath);
  provenance.sha256 = RequireString(input, where, key::input::kSha256);
  provenance.format = OptionalString(input, where, key::input::kFormat);
  provenance.samples = RequireCount(input, where, key::input::kSamples);
  provenance.valid_samples = RequireCount(input, where, key::input::kValidSamples);
  provenance.despiked_samples = RequireCount(input, where, key::input::kDespikedSamples);
  return provenance;
}

PhaseSeries ParsePhases(const json& root, const JsonWhere& top) {
  const JsonWhere where = top.Child(key::kPhases);
  const json& phases = RequireObject(root, top, key::kPhases);
  PhaseSeries series;
  series.phase_deg = RequireNumberArray(phases, where, key::phases::kPhaseDeg, std::string::npos);
  const std::size_t n = series.phase_deg.size();
  if (n == 0) BadSummary(where.Child(key::phases::kPhaseDeg), "is empty");
  series.arc_radius_mm = RequireNumberArray(phases, where, key::phases::kArcRadiusMm, n);
  series.arc_radius_sigma_mm = RequireNumberArray(phases, where, key::phases::kArcRadiusSigmaMm, n);
  series.center_axial_mm = RequireNumberArray(phases, where, key::phases::kCenterAxialMm, n);
  series.center_radial_mm = RequireNumberArray(phases, where, key::phases::kCenterRadialMm, n);
  series.arc_error_um = RequireNumberArray(phases, where, key::phases::kArcErrorUm, n);
  if (phases.contains(key::phases::kCenterAxialSigmaMm))
    series.center_axial_sigma_mm = RequireNumberArray(phases, where, key::phases::kCenterAxialSigmaMm, n);
  if (phases.contains(key::phases::kCenterRadialSigmaMm))
    series.center_radial_sigma_mm = RequireNumberArray(phases, where, key::phases::kCenterRadialSigmaMm, n);
  if (phases.contains(key::phases::kPointsInBand))
    series.points_in_band = RequireNumberArray(phases, where, key::phases::kPointsInBand, n);
  series.usable.assign(n, true);
  if (const auto it = phases.find(key::phases::kUsable); it != phases.end()) {
    const JsonWhere usable_where = where.Child(key::phases::kUsable);
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
  const JsonWhere where = top.Child(key::kAxial);
  const json& axial = RequireObject(root, top, key::kAxial);
  AxialSeries series;
  series.y_mm = RequireNumberArray(axial, where, key::axial::kYMm, std::string::npos);
  series.runout_um = RequireNumberArray(axial, where, key::axial::kRunoutUm, series.y_mm.size());
  series.roundness_um = RequireNumberArray(axial, where, key::axial::kRoundnessUm, series.y_mm.size());
  return series;
}

std::vector<ModelHarmonic> ParseHarmonics(const json& model, const JsonWhere& parent) {
  namespace hk = key::model::harmonic;
  const JsonWhere where = parent.Child(key::model::kRadiusHarmonics);
  const json& list = RequireKey(model, parent, key::model::kRadiusHarmonics);
  if (!list.is_array()) BadSummary(where, "is not an array");
  std::vector<ModelHarmonic> harmonics;
  for (std::size_t i = 0; i < list.size(); ++i) {
    const JsonWhere item = where.Child(std::to_string(i));
    if (!list[i].is_object()) BadSummary(item, "is not a JSON object");
    harmonics.push_back({.order = RequireInt(list[i], item, hk::kOrder),
                         .amplitude_um = RequireNumber(list[i], item, hk::kAmplitudeUm),
                         .amplitude_sigma_um = RequireNumber(list[i], item, hk::kAmplitudeSigmaUm),
                         .phase_deg = RequireNumber(list[i], item, hk::kPhaseDeg),
                         .phase_sigma_deg = RequireNumber(list[i], item, hk::kPhaseSigmaDeg)});
  }
  return harmonics;
}

// "model" is optional (schema 1.0, --no-model, a model that could not be fitted); when present,
// every key the report shows is required.
std::optional<ModelSummary> ParseModel(const json& root, const JsonWhere& top) {
  const auto it = root.find(key::kModel);
  if (it == root.end() || it->is_null()) return std::nullopt;
  namespace mk = key::model;
  const JsonWhere where = top.Child(key::kModel);
  const json& m = RequireObject(root, top, key::kModel);
  ModelSummary model;
  model.radius_knots = RequireInt(m, where, mk::kRadiusKnots);
  model.axial_knots = RequireInt(m, where, mk::kAxialKnots);
  model.runout_knots = RequireInt(m, where, mk::kRunoutKnots);
  model.knots_chosen_by = RequireString(m, where, mk::kKnotsChosenBy);
  model.residual_rms_um = RequireNumber(m, where, mk::kResidualRmsUm);
  model.noise_sigma_um = RequireNumber(m, where, mk::kNoiseSigmaUm);
  model.mean_arc_radius_mm = RequireNumber(m, where, mk::kMeanArcRadiusMm);
  model.mean_arc_radius_sigma_mm = RequireNumber(m, where, mk::kMeanArcRadiusSigmaMm);
  model.arc_radius_range_mm = RequireNumber(m, where, mk::kArcRadiusRangeMm);
  model.arc_radius_range_sigma_mm = RequireNumber(m, where, mk::kArcRadiusRangeSigmaMm);
  model.variation_chi2 = RequireNumber(m, where, mk::kVariationChi2);
  model.variation_dof = RequireInt(m, where, mk::kVariationDof);
  model.variation_p_value = RequireNumber(m, where, mk::kVariationPValue);
  model.significance_level = RequireNumber(m, where, mk::kSignificanceLevel);
  model.variation_significant = RequireBool(m, where, mk::kVariationSignificant);
  model.profile_pv_um = RequireNumber(m, where, mk::kProfilePvUm);
  model.radius_harmonics = ParseHarmonics(m, where);
  return model;
}

void ParseBand(const json& root, const JsonWhere& top, Summary& summary) {
  summary.band_low_mm = summary.mean_center_axial_mm - summary.band_half_width_mm;
  summary.band_high_mm = summary.mean_center_axial_mm + summary.band_half_width_mm;
  const auto it = root.find(key::kBandMm);
  if (it == root.end() || it->is_null()) return;
  const std::vector<double> band = RequireNumberArray(root, top, key::kBandMm, 2);
  summary.band_low_mm = band[0];
  summary.band_high_mm = band[1];
}

std::vector<std::string> ParseWarnings(const json& root, const JsonWhere& top) {
  std::vector<std::string> warnings;
  const auto it = root.find(key::kWarnings);
  if (it == root.end() || it->is_null()) return warnings;
  const JsonWhere where = top.Child(key::kWarnings);
  if (!it->is_array()) BadSummary(where, "is not an array of strings");
  for (std::size_t i = 0; i < it->size(); ++i) {
    if (!(*it)[i].is_string()) BadSummary(where.Child(std::to_string(i)), "is not a string");
    warnings.push_back((*it)[i].get<std::string>());
  }
  return warnings;
}

void ParseHeadline(const json& root, const JsonWhere& top, Summary& summary) {
  summary.spindle_rpm_nominal = RequireNumber(root, top, key::kSpindleRpmNominal);
  summary.spindle_rpm_estimated = RequireNumber(root, top, key::kSpindleRpmEstimated);
  summary.mean_arc_radius_mm = RequireNumber(root, top, key::kMeanArcRadiusMm);
  summary.mean_arc_radius_sigma_mm = RequireNumber(root, top, key::kMeanArcRadiusSigmaMm);
  summary.arc_radius_range_mm = RequireNumber(root, top, key::kArcRadiusRangeMm);
  summary.arc_radius_fluctuation_pct = RequireNumber(root, top, key::kArcRadiusFluctuationPct);
  summary.mean_center_axial_mm = RequireNumber(root, top, key::kMeanCenterAxialMm);
  summary.center_axial_deviation_mm = RequireNumber(root, top, key::kCenterAxialDeviationMm);
  summary.band_half_width_mm = RequireNumber(root, top, key::kBandHalfWidthMm);
  summary.max_arc_error_um = RequireNumber(root, top, key::kMaxArcErrorUm);
  summary.max_runout_um = RequireNumber(root, top, key::kMaxRunoutUm);
  summary.max_roundness_um = RequireNumber(root, top, key::kMaxRoundnessUm);
  summary.noise_sigma_um = OptionalNumber(root, top, key::kNoiseSigmaUm);
  summary.map_sigma_um = OptionalNumber(root, top, key::kMapSigmaUm);
  summary.spindle_rpm_source = OptionalString(root, top, key::kSpindleRpmSource);
  summary.mean_center_axial_sigma_mm = OptionalNumber(root, top, key::kMeanCenterAxialSigmaMm);
  summary.arc_radius_std_mm = OptionalNumber(root, top, key::kArcRadiusStdMm);
  summary.arc_radius_noise_std_mm = OptionalNumber(root, top, key::kArcRadiusNoiseStdMm);
  summary.arc_radius_excess_std_mm = OptionalNumber(root, top, key::kArcRadiusExcessStdMm);
  summary.runout_note = OptionalString(root, top, key::kRunoutNote);
}

// A file without schema_version was written before versions were recorded: read it as 1.0.
void CheckSummaryVersion(const json& root, const JsonWhere& top) {
  const std::string version = OptionalString(root, top, key::kSchemaVersion);
  const bool recorded = root.contains(key::kSchemaVersion) && !root.at(key::kSchemaVersion).is_null();
  schema::CheckVersion(recorded ? std::optional<std::string>(version) : std::nullopt, key::kVersion, top.file,
                       fmt::format("key '{}'", key::kSchemaVersion), kSummaryStage);
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

std::vector<double> ReadDataset(const hdf5::File& file, std::string_view dataset_path,
                                const std::vector<hsize_t>& expected_shape) {
  const std::string dataset(dataset_path);
  if (!file.HasObject(dataset)) BadMap(file.path(), dataset, "is missing");
  const std::vector<hsize_t> shape = file.Shape(dataset);
  if (shape != expected_shape) {
    auto text = [](const std::vector<hsize_t>& dims) { return fmt::format("[{}]", fmt::join(dims, ", ")); };
    BadMap(file.path(), dataset, "has shape " + text(shape) + ", expected " + text(expected_shape));
  }
  return file.ReadDoubles(dataset);
}

std::vector<double> ReadAxisDataset(const hdf5::File& file, std::string_view dataset_path) {
  const std::string dataset(dataset_path);
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

// /model's datasets, when the group is there; each of the shape the writer gives it.
std::optional<ModelCurves> ReadModelCurves(const hdf5::File& file, std::size_t n_phase, std::size_t n_y) {
  if (!file.HasObject(std::string(h5::kModelGroup))) return std::nullopt;
  const std::vector<hsize_t> phases = {n_phase};
  ModelCurves model;
  model.arc_radius_mm = ReadDataset(file, h5::kModelArcRadiusMm, phases);
  model.arc_radius_sigma_mm = ReadDataset(file, h5::kModelArcRadiusSigmaMm, phases);
  model.center_axial_mm = ReadDataset(file, h5::kModelCenterAxialMm, phases);
  model.center_axial_sigma_mm = ReadDataset(file, h5::kModelCenterAxialSigmaMm, phases);
  model.center_radial_mm = ReadDataset(file, h5::kModelCenterRadialMm, phases);
  model.center_radial_sigma_mm = ReadDataset(file, h5::kModelCenterRadialSigmaMm, phases);
  model.profile_u_mm = ReadAxisDataset(file, h5::kModelProfileUMm);
  const std::vector<hsize_t> profile = {model.profile_u_mm.size()};
  model.profile_error_um = ReadDataset(file, h5::kModelProfileErrorUm, profile);
  model.profile_error_sigma_um = ReadDataset(file, h5::kModelProfileErrorSigmaUm, profile);
  // The writer leaves the residual map out when it could not make one of the map's shape.
  if (file.HasObject(std::string(h5::kModelResidualUm)))
    model.residual_um = ReadDataset(file, h5::kModelResidualUm, {n_phase, n_y});
  return model;
}

// "characteristics" is optional (schema < 1.3, --no-uncertainty); an entry without a value_* is
// refused naming it.
std::map<std::string, Summary::Characteristic> ParseCharacteristics(const json& root, const JsonWhere& top) {
  std::map<std::string, Summary::Characteristic> out;
  const auto block = root.find(key::kCharacteristics);
  if (block == root.end() || block->is_null()) return out;
  if (!block->is_object()) BadSummary(top.Child(key::kCharacteristics), "is not a JSON object");
  const auto number = [](const json& object, std::string_view field) {
    const auto it = object.find(field);
    return it != object.end() && it->is_number() ? it->get<double>()
                                                 : std::numeric_limits<double>::quiet_NaN();
  };
  const auto text = [](const json& object, std::string_view field) {
    const auto it = object.find(field);
    return it != object.end() && it->is_string() ? it->get<std::string>() : std::string();
  };
  for (const auto& [name, item] : block->items()) {
    const JsonWhere where = top.Child(key::kCharacteristics).Child(name);
    if (!item.is_object()) BadSummary(where, "is not a JSON object");
    std::string unit;
    for (const char* candidate : {"um", "mm", "pct"}) {
      if (item.contains(std::string("value_") + candidate)) unit = candidate;
    }
    if (unit.empty()) BadSummary(where, "has no value_um or value_mm");
    Summary::Characteristic c;
    c.value = number(item, "value_" + unit);
    c.expanded = number(item, "U");
    c.coverage_factor = number(item, "k");
    c.where = text(item, "where");
    c.decision = text(item, "decision");
    c.rule = text(item, "rule");
    if (const double at = number(item, "at_y_mm"); std::isfinite(at)) c.at_y_mm = at;
    if (const auto op = item.find("operator"); op != item.end() && op->is_object()) {
      c.operator_text = text(*op, "short");
      c.association = text(*op, "association");
      if (const auto filter = op->find("filter"); filter != op->end() && filter->is_object()) {
        const double cutoff = number(*filter, "cutoff_upr");
        if (std::isfinite(cutoff)) c.cutoff_upr = cutoff;
      }
    }
    out[name + "_" + unit] = c;
  }
  return out;
}

}  // namespace

Summary ParseSummary(const std::string& text, const std::string& name) {
  const json root = ParseJsonText(text, name, kSummaryStage);
  const JsonWhere top{name, ""};
  if (!root.is_object())
    throw Error(ErrorCode::kBadInput, kSummaryStage, "'" + name + "' is not a JSON object");
  CheckSummaryVersion(root, top);
  Summary summary;
  summary.arcwheel_version = RequireString(root, top, key::kArcwheelVersion);
  summary.schema_version = OptionalString(root, top, key::kSchemaVersion);
  summary.input = ParseInput(root, top);
  ParseHeadline(root, top, summary);
  ParseBand(root, top, summary);
  summary.phases = ParsePhases(root, top);
  summary.axial = ParseAxial(root, top);
  summary.processing = RequireObject(root, top, key::kProcessing);
  if (const auto it = root.find(key::kScan); it != root.end() && !it->is_null()) {
    if (!it->is_object()) BadSummary(top.Child(key::kScan), "is not a JSON object");
    summary.scan = *it;
  }
  summary.warnings = ParseWarnings(root, top);
  summary.model = ParseModel(root, top);
  // "uncertainty" is optional (schema < 1.2, --no-uncertainty); a number that is null reads NaN.
  if (const auto u = root.find(key::kUncertainty); u != root.end() && u->is_object()) {
    namespace uk = key::uncertainty;
    const auto number = [](const json& object, std::string_view field) {
      const auto it = object.find(field);
      return it != object.end() && it->is_number() ? it->get<double>()
                                                   : std::numeric_limits<double>::quiet_NaN();
    };
    summary.coverage_probability = number(*u, uk::kCoverageProbability);
    if (const auto q = u->find(uk::kQuantities); q != u->end() && q->is_object()) {
      for (const auto& [quantity, item] : q->items()) {
        if (!item.is_object()) continue;
        double type_a = std::numeric_limits<double>::quiet_NaN();
        if (const auto c = item.find(uk::quantity::kContributions); c != item.end() && c->is_array()) {
          for (const json& line : *c) {
            if (line.is_object() && line.value(std::string(uk::quantity::contribution::kType), "") == "A")
              type_a = number(line, uk::quantity::contribution::kContribution);
          }
        }
        summary.uncertainty[quantity] = {number(item, uk::quantity::kValue),
                                         number(item, uk::quantity::kExpanded),
                                         number(item, uk::quantity::kCoverageFactor),
                                         number(item, uk::quantity::kStandardUncertainty), type_a};
      }
    }
  }
  summary.characteristics = ParseCharacteristics(root, top);
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
  const std::string root(h5::kRoot);
  schema::CheckVersion(file.ReadAttributeString(root, std::string(h5::kSchemaVersionAttribute)), h5::kVersion,
                       path.string(), fmt::format("attribute '{}'", h5::kSchemaVersionAttribute), kMapStage);
  map.phase_deg = ReadAxisDataset(file, h5::kMapPhaseDeg);
  map.y_mm = ReadAxisDataset(file, h5::kMapYMm);
  const std::vector<hsize_t> grid = {map.n_phase(), map.n_y()};
  map.rho_mm = ReadDataset(file, h5::kMapRhoMm, grid);
  map.form_error_um = ReadDataset(file, h5::kMapFormErrorUm, grid);
  map.sample_count = ReadDataset(file, h5::kMapSampleCount, grid);
  map.despiked_count = ReadDataset(file, h5::kMapDespikedCount, grid);
  map.model = ReadModelCurves(file, map.n_phase(), map.n_y());
  map.arcwheel_version =
      file.ReadAttributeString(root, std::string(h5::kArcwheelVersionAttribute)).value_or("");
  map.input_sha256 = file.ReadAttributeString(root, std::string(h5::kInputSha256Attribute)).value_or("");
  return map;
}

ReportInputs ReadReportInputs(const std::filesystem::path& outdir) {
  ReportInputs inputs;
  inputs.summary_path = outdir / key::kFileName;
  inputs.map_path = outdir / h5::kFileName;
  inputs.summary = ReadSummary(inputs.summary_path);
  inputs.map = ReadWheelMap(inputs.map_path);
  const Summary& summary = inputs.summary;
  if (!inputs.map.input_sha256.empty() && inputs.map.input_sha256 != summary.input.sha256) {
    throw Error(
        ErrorCode::kBadInput, kMapStage,
        fmt::format("'{}' attribute '{}' ({}) differs from '{}' key '{}.{}' ({}): the two files "
                    "describe different scans",
                    inputs.map_path.string(), h5::kInputSha256Attribute, inputs.map.input_sha256,
                    inputs.summary_path.string(), key::kInput, key::input::kSha256, summary.input.sha256));
  }
  if (inputs.map.n_phase() != summary.phases.phase_deg.size()) {
    throw Error(
        ErrorCode::kBadInput, kMapStage,
        fmt::format("'{}' dataset '{}' has {} phases but '{}' key '{}.{}' has {}", inputs.map_path.string(),
                    h5::kMapPhaseDeg, inputs.map.n_phase(), inputs.summary_path.string(), key::kPhases,
                    key::phases::kPhaseDeg, summary.phases.phase_deg.size()));
  }
  for (std::size_t i = 0; i < inputs.map.n_phase(); ++i) {
    if (std::abs(inputs.map.phase_deg[i] - summary.phases.phase_deg[i]) > 1e-6) {
      throw Error(ErrorCode::kBadInput, kMapStage,
                  fmt::format("'{}' dataset '{}' [{}] = {} differs from '{}' key '{}.{}.{}' = {}",
                              inputs.map_path.string(), h5::kMapPhaseDeg, i, inputs.map.phase_deg[i],
                              inputs.summary_path.string(), key::kPhases, key::phases::kPhaseDeg, i,
                              summary.phases.phase_deg[i]));
    }
  }
  if (summary.model && !inputs.map.model) {
    throw Error(
        ErrorCode::kBadInput, kMapStage,
        fmt::format("'{}' group '{}' is missing, but '{}' has key '{}': the two files come from "
                    "different runs",
                    inputs.map_path.string(), h5::kModelGroup, inputs.summary_path.string(), key::kModel));
  }
  return inputs;
}

}  // namespace arcwheel::reports
