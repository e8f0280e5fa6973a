#pragma once
// The results store's schema (docs/store.md): the one place that spells its tables and columns,
// which are also the keys of `arcwheel db export --json` and the header of `--csv`. The same
// schema on SQLite and PostgreSQL. Version 1 is the first released layout; each later version is
// a migration from the one before (store/store.cc) that keeps every row.

#include <string_view>

namespace arcwheel::schema::store {

// The version a store is created at and migrated to.
inline constexpr int kLatestVersion = 2;

// One row: the store's schema version.
inline constexpr std::string_view kSchemaVersionTable = "schema_version";
namespace schema_version {
inline constexpr std::string_view kVersion = "version";
}  // namespace schema_version

// One row per recorded run of `process`, `toolpath` or `polish` (`batch` records its scans'
// `process` runs, `regenerate` its three steps).
inline constexpr std::string_view kRunsTable = "runs";
namespace runs {
inline constexpr std::string_view kId = "id";
inline constexpr std::string_view kCommand = "command";  // "process", "toolpath", "polish"
inline constexpr std::string_view kVia =
    "via";  // the command that ran it: "process", "batch", "regenerate", ...
inline constexpr std::string_view kWheelId = "wheel_id";  // summary.json scan.wheel_id; "" when not recorded
inline constexpr std::string_view kScanTimestamp =
    "scan_timestamp";  // summary.json scan.timestamp, as recorded
inline constexpr std::string_view kScanTimeS =
    "scan_time_s";  // the same, seconds since 1970 UTC; NULL if none
inline constexpr std::string_view kRecordedAt = "recorded_at";  // ISO 8601 UTC, when the run was recorded
inline constexpr std::string_view kArcwheelVersion = "arcwheel_version";
inline constexpr std::string_view kOutputFolder = "output_folder";  // absolute
inline constexpr std::string_view kOptions = "options";             // JSON text: the options as used
// Version 2.
inline constexpr std::string_view kHost = "host";  // the machine that ran it
// The values of kCommand.
inline constexpr std::string_view kProcess = "process";
inline constexpr std::string_view kToolpath = "toolpath";
inline constexpr std::string_view kPolish = "polish";
}  // namespace runs

// The files a run read: one row per input.
inline constexpr std::string_view kInputsTable = "inputs";
namespace inputs {
inline constexpr std::string_view kRunId = "run_id";
inline constexpr std::string_view kRole = "role";  // "scan", "job", "wheel", "error_map"
inline constexpr std::string_view kPath = "path";  // absolute
inline constexpr std::string_view kSha256 = "sha256";
// The values of kRole.
inline constexpr std::string_view kScan = "scan";
inline constexpr std::string_view kJob = "job";
inline constexpr std::string_view kWheel = "wheel";
inline constexpr std::string_view kErrorMap = "error_map";
}  // namespace inputs

// Every headline number of a run, one row per characteristic (the shape SPC tools import).
inline constexpr std::string_view kNumbersTable = "numbers";
namespace numbers {
inline constexpr std::string_view kRunId = "run_id";
inline constexpr std::string_view kCharacteristic = "characteristic";  // the output file's key
inline constexpr std::string_view kValue = "value";
inline constexpr std::string_view kSigma = "sigma";  // 1 sigma in the value's unit; NULL if none
inline constexpr std::string_view kUnit = "unit";    // "mm", "um", "%", "s", ...
// Version 2: the expanded uncertainty (k = 2) and the conformity decision, NULL until recorded.
inline constexpr std::string_view kExpandedUncertainty = "expanded_uncertainty";
inline constexpr std::string_view kDecision = "decision";
}  // namespace numbers

// `arcwheel db export`: the run's columns beside each number's (runs::kId named run_id); the JSON
// export is {"schema_version": N, "rows": [...]}.
inline constexpr std::string_view kExportRunId = "run_id";
inline constexpr std::string_view kExportSchemaVersion = "schema_version";
inline constexpr std::string_view kExportRows = "rows";

}  // namespace arcwheel::schema::store
