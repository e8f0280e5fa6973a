#include "store/queries.h"

#include <fmt/format.h>

#include <cmath>
#include <limits>

#include "core/error.h"
#include "core/json_text.h"
#include "core/nan.h"
#include "schema/summary.h"

namespace arcwheel::store {
namespace {

namespace s = schema::store;
namespace k = schema::summary;
using nlohmann::json;
constexpr const char* kQueriesStage = "store";

double CharacteristicValue(const StoredRun& run, std::string_view characteristic) {
  const StoredNumber* number = run.Number(std::string(characteristic));
  return number != nullptr ? number->value : kNaN;
}

std::vector<StoredRun> Scans(Store& store, const std::string& wheel_id,
                             const std::optional<double>& since_s) {
  if (wheel_id.empty()) throw Error(ErrorCode::kInvalidOption, kQueriesStage, "--wheel needs a wheel id");
  std::vector<StoredRun> runs =
      store.Runs({.wheel_id = wheel_id, .command = std::string(s::runs::kProcess), .since_s = since_s});
  if (runs.empty()) {
    throw Error(ErrorCode::kBadInput, kQueriesStage,
                fmt::format("'{}' holds no scan of wheel '{}'{}", store.Name(), wheel_id,
                            since_s ? " since the given date" : ""));
  }
  return runs;
}

// The columns of an export row, in order.
const std::vector<std::string_view>& ExportColumns() {
  static const std::vector<std::string_view> columns = {s::kExportRunId,
                                                        s::runs::kCommand,
                                                        s::runs::kVia,
                                                        s::runs::kWheelId,
                                                        s::runs::kScanTimestamp,
                                                        s::runs::kRecordedAt,
                                                        s::numbers::kCharacteristic,
                                                        s::numbers::kValue,
                                                        s::numbers::kSigma,
                                                        s::numbers::kUnit,
                                                        s::numbers::kExpandedUncertainty,
                                                        s::numbers::kDecision,
                                                        s::runs::kOutputFolder,
                                                        s::runs::kArcwheelVersion,
                                                        s::runs::kHost};
  return columns;
}

json Number(const std::optional<double>& value) {
  return value && std::isfinite(*value) ? json(*value) : json(nullptr);
}

json Row(const StoredRun& run, const StoredNumber& number) {
  json row = json::object();
  row[std::string(s::kExportRunId)] = run.id;
  row[std::string(s::runs::kCommand)] = run.command;
  row[std::string(s::runs::kVia)] = run.via;
  row[std::string(s::runs::kWheelId)] = run.wheel_id;
  row[std::string(s::runs::kScanTimestamp)] = run.scan_timestamp;
  row[std::string(s::runs::kRecordedAt)] = run.recorded_at;
  row[std::string(s::numbers::kCharacteristic)] = number.characteristic;
  row[std::string(s::numbers::kValue)] = Number(number.value);
  row[std::string(s::numbers::kSigma)] = Number(number.sigma);
  row[std::string(s::numbers::kUnit)] = number.unit;
  row[std::string(s::numbers::kExpandedUncertainty)] = Number(number.expanded_uncertainty);
  row[std::string(s::numbers::kDecision)] = number.decision.empty() ? json(nullptr) : json(number.decision);
  row[std::string(s::runs::kOutputFolder)] = run.output_folder;
  row[std::string(s::runs::kArcwheelVersion)] = run.arcwheel_version;
  row[std::string(s::runs::kHost)] = run.host;
  return row;
}

// RFC 4180: a cell with a comma, quote or line break is quoted, its quotes doubled.
std::string CsvCell(const json& value) {
  if (value.is_null()) return "";
  std::string text = value.is_string() ? value.get<std::string>() : JsonText(value);
  if (text.find_first_of(",\"\r\n") == std::string::npos) return text;
  std::string quoted = "\"";
  for (char c : text) {
    if (c == '"') quoted += '"';
    quoted += c;
  }
  return quoted + "\"";
}

}  // namespace

reports::History HistoryFromStore(Store& store, const std::string& wheel_id,
                                  const std::optional<double>& since_s,
                                  const std::vector<double>& dressing_times_s,
                                  const std::vector<std::string>& dressing_timestamps) {
  std::vector<reports::HistoryScan> scans;
  for (const StoredRun& run : Scans(store, wheel_id, since_s)) {
    if (!run.scan_time_s) {
      throw Error(ErrorCode::kBadInput, "reports.history",
                  fmt::format("'{}' run {} ({}) has no readable scan timestamp ('{}')", store.Name(), run.id,
                              run.output_folder, run.scan_timestamp));
    }
    reports::HistoryScan scan;
    scan.folder = run.output_folder;
    scan.timestamp = run.scan_timestamp;
    scan.time_s = *run.scan_time_s;
    reports::Summary& summary = scan.summary;
    const StoredNumber* radius = run.Number(std::string(k::kMeanArcRadiusMm));
    summary.mean_arc_radius_mm = radius != nullptr ? radius->value : kNaN;
    summary.mean_arc_radius_sigma_mm = radius != nullptr && radius->sigma ? *radius->sigma : kNaN;
    summary.arc_radius_range_mm = CharacteristicValue(run, k::kArcRadiusRangeMm);
    summary.center_axial_deviation_mm = CharacteristicValue(run, k::kCenterAxialDeviationMm);
    summary.max_arc_error_um = CharacteristicValue(run, k::kMaxArcErrorUm);
    summary.max_runout_um = CharacteristicValue(run, k::kMaxRunoutUm);
    summary.max_roundness_um = CharacteristicValue(run, k::kMaxRoundnessUm);
    summary.scan = {{std::string(k::scan::kWheelId), run.wheel_id},
                    {std::string(k::scan::kTimestamp), run.scan_timestamp}};
    scans.push_back(std::move(scan));
  }
  return reports::AssembleHistory(wheel_id, std::move(scans), dressing_times_s, dressing_timestamps);
}

std::pair<std::filesystem::path, std::filesystem::path> ComparisonFolders(
    Store& store, const std::string& wheel_id, const std::optional<double>& since_s) {
  const std::vector<StoredRun> runs = Scans(store, wheel_id, since_s);
  if (runs.size() < 2) {
    throw Error(ErrorCode::kBadInput, kQueriesStage,
                fmt::format("'{}' holds {} scan of wheel '{}'{}: a comparison needs two", store.Name(),
                            runs.size(), wheel_id, since_s ? " since the given date" : ""));
  }
  const StoredRun& before = since_s ? runs.front() : runs[runs.size() - 2];
  return {before.output_folder, runs.back().output_folder};
}

std::string ExportCsv(const std::vector<StoredRun>& runs) {
  std::string csv;
  for (std::string_view column : ExportColumns()) {
    if (!csv.empty()) csv += ',';
    csv += column;
  }
  csv += "\n";
  for (const StoredRun& run : runs) {
    for (const StoredNumber& number : run.numbers) {
      const json row = Row(run, number);
      std::string line;
      for (std::string_view column : ExportColumns()) {
        if (!line.empty()) line += ',';
        line += CsvCell(row.at(std::string(column)));
      }
      csv += line + "\n";
    }
  }
  return csv;
}

json ExportJson(const std::vector<StoredRun>& runs) {
  json rows = json::array();
  for (const StoredRun& run : runs) {
    for (const StoredNumber& number : run.numbers) rows.push_back(Row(run, number));
  }
  return {{std::string(s::kExportSchemaVersion), s::kLatestVersion}, {std::string(s::kExportRows), rows}};
}

}  // namespace arcwheel::store
