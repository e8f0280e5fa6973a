#include "store/store.h"

#include <fmt/format.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <ctime>
#include <map>

#include "core/error.h"
#include "core/version.h"
#include "reports/history.h"
#include "store/database.h"

namespace arcwheel::store {
namespace {

namespace s = schema::store;
using internal::Database;
using internal::Value;
constexpr const char* kStoreStage = "store";

bool IsPostgresUrl(const std::string& location) {
  return location.rfind("postgresql://", 0) == 0 || location.rfind("postgres://", 0) == 0;
}

std::string UtcNow() {
  const std::time_t now = std::chrono::system_clock::to_time_t(std::chrono::system_clock::now());
  std::tm utc{};
  gmtime_r(&now, &utc);
  char text[32];
  std::strftime(text, sizeof text, "%Y-%m-%dT%H:%M:%SZ", &utc);
  return text;
}

std::string HostName() {
  char name[256] = {};
  if (gethostname(name, sizeof name - 1) != 0) return "";
  return name;
}

// Version 1: the first layout.
void CreateVersion1(Database& db) {
  db.Execute(fmt::format("CREATE TABLE {} ({} INTEGER NOT NULL)", s::kSchemaVersionTable,
                         s::schema_version::kVersion));
  db.Execute(fmt::format(
      "CREATE TABLE {} ({} {}, {} TEXT NOT NULL, {} TEXT NOT NULL, {} TEXT NOT NULL, {} TEXT NOT NULL, "
      "{} DOUBLE PRECISION, {} TEXT NOT NULL, {} TEXT NOT NULL, {} TEXT NOT NULL, {} TEXT NOT NULL)",
      s::kRunsTable, s::runs::kId, db.AutoIdType(), s::runs::kCommand, s::runs::kVia, s::runs::kWheelId,
      s::runs::kScanTimestamp, s::runs::kScanTimeS, s::runs::kRecordedAt, s::runs::kArcwheelVersion,
      s::runs::kOutputFolder, s::runs::kOptions));
  db.Execute(fmt::format(
      "CREATE TABLE {} ({} BIGINT NOT NULL REFERENCES {}({}), {} TEXT NOT NULL, {} TEXT NOT NULL, "
      "{} TEXT NOT NULL)",
      s::kInputsTable, s::inputs::kRunId, s::kRunsTable, s::runs::kId, s::inputs::kRole, s::inputs::kPath,
      s::inputs::kSha256));
  db.Execute(fmt::format(
      "CREATE TABLE {} ({} BIGINT NOT NULL REFERENCES {}({}), {} TEXT NOT NULL, {} DOUBLE PRECISION, "
      "{} DOUBLE PRECISION, {} TEXT NOT NULL)",
      s::kNumbersTable, s::numbers::kRunId, s::kRunsTable, s::runs::kId, s::numbers::kCharacteristic,
      s::numbers::kValue, s::numbers::kSigma, s::numbers::kUnit));
  db.Execute(
      fmt::format("INSERT INTO {} ({}) VALUES (1)", s::kSchemaVersionTable, s::schema_version::kVersion));
}

// 1 -> 2: the machine of each run (existing runs: ""), each number's expanded uncertainty and
// decision (existing numbers: NULL), and an index for the queries by wheel and time.
void MigrateTo2(Database& db) {
  db.Execute(
      fmt::format("ALTER TABLE {} ADD COLUMN {} TEXT NOT NULL DEFAULT ''", s::kRunsTable, s::runs::kHost));
  db.Execute(fmt::format("ALTER TABLE {} ADD COLUMN {} DOUBLE PRECISION", s::kNumbersTable,
                         s::numbers::kExpandedUncertainty));
  db.Execute(fmt::format("ALTER TABLE {} ADD COLUMN {} TEXT", s::kNumbersTable, s::numbers::kDecision));
  db.Execute(fmt::format("CREATE INDEX {0}_by_wheel ON {0} ({1}, {2})", s::kRunsTable, s::runs::kWheelId,
                         s::runs::kScanTimeS));
  db.Execute(fmt::format("CREATE INDEX {0}_by_run ON {0} ({1})", s::kNumbersTable, s::numbers::kRunId));
  db.Execute(fmt::format("CREATE INDEX {0}_by_run ON {0} ({1})", s::kInputsTable, s::inputs::kRunId));
}

// The migration to version v + 1 is kMigrations[v - 1].
using Migration = void (*)(Database&);
const std::vector<Migration> kMigrations = {MigrateTo2};
static_assert(s::kLatestVersion == 2, "a new schema version needs its migration in kMigrations");

int VersionOf(Database& db) {
  if (!db.HasTable(std::string(s::kSchemaVersionTable))) return 0;
  const auto rows =
      db.Query(fmt::format("SELECT {} FROM {}", s::schema_version::kVersion, s::kSchemaVersionTable));
  if (rows.size() != 1 || !internal::AsInteger(rows[0][0])) {
    throw Error(ErrorCode::kBadInput, kStoreStage,
                fmt::format("'{}': table '{}' does not hold one version", db.Name(), s::kSchemaVersionTable));
  }
  return static_cast<int>(*internal::AsInteger(rows[0][0]));
}

void SetVersion(Database& db, int version) {
  db.Execute(fmt::format("UPDATE {} SET {} = $1", s::kSchemaVersionTable, s::schema_version::kVersion),
             {static_cast<std::int64_t>(version)});
}

Value Optional(const std::optional<double>& value) { return value ? Value(*value) : Value(std::monostate{}); }

std::string Text(const Value& value) { return internal::AsText(value).value_or(""); }

}  // namespace

const StoredNumber* StoredRun::Number(const std::string& characteristic) const {
  for (const StoredNumber& number : numbers) {
    if (number.characteristic == characteristic) return &number;
  }
  return nullptr;
}

std::string StoreLocation(const std::string& option) {
  if (!option.empty()) return option;
  const char* environment = std::getenv("ARCWHEEL_DB");
  return environment != nullptr ? environment : "";
}

double ParseSince_s(const std::string& text, const std::string& option) {
  const std::string date_time = text.size() == 10 ? text + "T00:00:00Z" : text;
  try {
    return reports::ParseTimestamp_s(date_time, option);
  } catch (const Error&) {
    throw Error(ErrorCode::kInvalidOption, kStoreStage,
                fmt::format("{} '{}' is not a date (YYYY-MM-DD) or an ISO 8601 date and time", option, text));
  }
}

Store::Store(std::unique_ptr<internal::Database> database) : database_(std::move(database)) {}
Store::Store(Store&&) noexcept = default;
Store& Store::operator=(Store&&) noexcept = default;
Store::~Store() = default;

Store Store::Open(const std::string& location) {
  if (location.empty())
    throw Error(ErrorCode::kInvalidOption, kStoreStage, "no store given (--db or ARCWHEEL_DB)");
  return Store(IsPostgresUrl(location) ? internal::OpenPostgres(location) : internal::OpenSqlite(location));
}

Store Store::OpenForRecording(const std::string& location) {
  Store store = Open(location);
  if (store.Version() == 0) store.Init();
  store.RequireVersion(s::kLatestVersion);
  return store;
}

const std::string& Store::Name() const { return database_->Name(); }

int Store::Version() { return VersionOf(*database_); }

void Store::RequireVersion(int version) {
  const int found = Version();
  if (found == version) return;
  if (found < version) {
    throw Error(ErrorCode::kBadInput, kStoreStage,
                fmt::format("'{}' is at schema version {}, this arcwheel writes version {}: run `arcwheel db "
                            "migrate --db {}` first",
                            Name(), found, version, Name()));
  }
  throw Error(ErrorCode::kBadInput, kStoreStage,
              fmt::format("'{}' is at schema version {}, newer than this arcwheel's {}: use a newer arcwheel",
                          Name(), found, version));
}

void Store::Init(int version) {
  if (version < 1 || version > s::kLatestVersion) {
    throw Error(ErrorCode::kInvalidOption, kStoreStage,
                fmt::format("schema version {} violates 1 .. {}", version, s::kLatestVersion));
  }
  database_->WriteTransaction([&] {
    // Checked inside the transaction: another writer may have created it meanwhile.
    const int found = VersionOf(*database_);
    if (found == version) return;
    if (found != 0) {
      throw Error(ErrorCode::kBadInput, kStoreStage,
                  fmt::format("'{}' holds schema version {} already (`arcwheel db migrate` updates it)",
                              Name(), found));
    }
    CreateVersion1(*database_);
    for (int v = 1; v < version; ++v) kMigrations[static_cast<size_t>(v - 1)](*database_);
    SetVersion(*database_, version);
  });
}

std::pair<int, int> Store::Migrate() {
  std::pair<int, int> versions;
  database_->WriteTransaction([&] {
    const int found = VersionOf(*database_);
    if (found == 0)
      throw Error(ErrorCode::kBadInput, kStoreStage,
                  fmt::format("'{}' holds no store: run `arcwheel db init`", Name()));
    if (found > s::kLatestVersion) RequireVersion(s::kLatestVersion);
    for (int v = found; v < s::kLatestVersion; ++v) kMigrations[static_cast<size_t>(v - 1)](*database_);
    SetVersion(*database_, s::kLatestVersion);
    versions = {found, s::kLatestVersion};
  });
  return versions;
}

void Store::Record(std::vector<StoredRun>& runs) {
  database_->WriteTransaction([&] {
    RequireVersion(s::kLatestVersion);
    for (StoredRun& run : runs) {
      if (run.recorded_at.empty()) run.recorded_at = UtcNow();
      if (run.arcwheel_version.empty()) run.arcwheel_version = kVersion;
      if (run.host.empty()) run.host = HostName();
      const auto id = database_->Query(
          fmt::format(
              "INSERT INTO {} ({}, {}, {}, {}, {}, {}, {}, {}, {}, {}) VALUES ($1, $2, $3, $4, $5, $6, $7, "
              "$8, $9, $10) RETURNING {}",
              s::kRunsTable, s::runs::kCommand, s::runs::kVia, s::runs::kWheelId, s::runs::kScanTimestamp,
              s::runs::kScanTimeS, s::runs::kRecordedAt, s::runs::kArcwheelVersion, s::runs::kOutputFolder,
              s::runs::kOptions, s::runs::kHost, s::runs::kId),
          {run.command, run.via, run.wheel_id, run.scan_timestamp, Optional(run.scan_time_s), run.recorded_at,
           run.arcwheel_version, run.output_folder, run.options, run.host});
      if (id.size() != 1 || !internal::AsInteger(id[0][0])) {
        throw Error(ErrorCode::kIo, kStoreStage, fmt::format("'{}': no id for the recorded run", Name()));
      }
      run.id = *internal::AsInteger(id[0][0]);
      for (const StoredInput& input : run.inputs) {
        database_->Execute(
            fmt::format("INSERT INTO {} ({}, {}, {}, {}) VALUES ($1, $2, $3, $4)", s::kInputsTable,
                        s::inputs::kRunId, s::inputs::kRole, s::inputs::kPath, s::inputs::kSha256),
            {run.id, input.role, input.path, input.sha256});
      }
      for (const StoredNumber& number : run.numbers) {
        database_->Execute(
            fmt::format("INSERT INTO {} ({}, {}, {}, {}, {}, {}, {}) VALUES ($1, $2, $3, $4, $5, $6, $7)",
                        s::kNumbersTable, s::numbers::kRunId, s::numbers::kCharacteristic, s::numbers::kValue,
                        s::numbers::kSigma, s::numbers::kUnit, s::numbers::kExpandedUncertainty,
                        s::numbers::kDecision),
            {run.id, number.characteristic, number.value, Optional(number.sigma), number.unit,
             Optional(number.expanded_uncertainty),
             number.decision.empty() ? Value(std::monostate{}) : Value(number.decision)});
      }
    }
  });
}

bool Store::HasRun(const std::string& command, const std::string& output_folder, const std::string& role,
                   const std::string& sha256) {
  RequireVersion(s::kLatestVersion);
  return !database_
              ->Query(fmt::format(
                          "SELECT r.{} FROM {} r JOIN {} i ON i.{} = r.{} WHERE r.{} = $1 AND r.{} = $2 AND "
                          "i.{} = $3 AND i.{} = $4",
                          s::runs::kId, s::kRunsTable, s::kInputsTable, s::inputs::kRunId, s::runs::kId,
                          s::runs::kCommand, s::runs::kOutputFolder, s::inputs::kRole, s::inputs::kSha256),
                      {command, output_folder, role, sha256})
              .empty();
}

std::vector<StoredRun> Store::Runs(const RunFilter& filter) {
  RequireVersion(s::kLatestVersion);
  std::string where = "1 = 1";
  std::vector<Value> parameters;
  if (!filter.wheel_id.empty()) {
    parameters.emplace_back(filter.wheel_id);
    where += fmt::format(" AND {} = ${}", s::runs::kWheelId, parameters.size());
  }
  if (!filter.command.empty()) {
    parameters.emplace_back(filter.command);
    where += fmt::format(" AND {} = ${}", s::runs::kCommand, parameters.size());
  }
  if (filter.since_s) {
    parameters.emplace_back(*filter.since_s);
    where += fmt::format(" AND {} >= ${}", s::runs::kScanTimeS, parameters.size());
  }
  std::vector<StoredRun> runs;
  std::map<std::int64_t, size_t> by_id;
  // NULL scan times (toolpath, polish) sort by recording order after the scans.
  for (const auto& row : database_->Query(
           fmt::format("SELECT {}, {}, {}, {}, {}, {}, {}, {}, {}, {}, {} FROM {} WHERE {} ORDER BY {} IS "
                       "NULL, {}, {}",
                       s::runs::kId, s::runs::kCommand, s::runs::kVia, s::runs::kWheelId,
                       s::runs::kScanTimestamp, s::runs::kScanTimeS, s::runs::kRecordedAt,
                       s::runs::kArcwheelVersion, s::runs::kOutputFolder, s::runs::kOptions, s::runs::kHost,
                       s::kRunsTable, where, s::runs::kScanTimeS, s::runs::kScanTimeS, s::runs::kId),
           parameters)) {
    StoredRun run;
    run.id = internal::AsInteger(row[0]).value_or(0);
    run.command = Text(row[1]);
    run.via = Text(row[2]);
    run.wheel_id = Text(row[3]);
    run.scan_timestamp = Text(row[4]);
    run.scan_time_s = internal::AsDouble(row[5]);
    run.recorded_at = Text(row[6]);
    run.arcwheel_version = Text(row[7]);
    run.output_folder = Text(row[8]);
    run.options = Text(row[9]);
    run.host = Text(row[10]);
    by_id[run.id] = runs.size();
    runs.push_back(std::move(run));
  }
  if (runs.empty()) return runs;
  const std::string selected = fmt::format("SELECT {} FROM {} WHERE {}", s::runs::kId, s::kRunsTable, where);
  for (const auto& row :
       database_->Query(fmt::format("SELECT {}, {}, {}, {} FROM {} WHERE {} IN ({}) ORDER BY {}",
                                    s::inputs::kRunId, s::inputs::kRole, s::inputs::kPath, s::inputs::kSha256,
                                    s::kInputsTable, s::inputs::kRunId, selected, s::inputs::kRunId),
                        parameters)) {
    const auto run = by_id.find(internal::AsInteger(row[0]).value_or(0));
    if (run == by_id.end()) continue;
    runs[run->second].inputs.push_back({Text(row[1]), Text(row[2]), Text(row[3])});
  }
  for (const auto& row :
       database_->Query(fmt::format("SELECT {}, {}, {}, {}, {}, {}, {} FROM {} WHERE {} IN ({})",
                                    s::numbers::kRunId, s::numbers::kCharacteristic, s::numbers::kValue,
                                    s::numbers::kSigma, s::numbers::kUnit, s::numbers::kExpandedUncertainty,
                                    s::numbers::kDecision, s::kNumbersTable, s::numbers::kRunId, selected),
                        parameters)) {
    const auto run = by_id.find(internal::AsInteger(row[0]).value_or(0));
    if (run == by_id.end()) continue;
    StoredNumber number;
    number.characteristic = Text(row[1]);
    number.value = internal::AsDouble(row[2]).value_or(std::numeric_limits<double>::quiet_NaN());
    number.sigma = internal::AsDouble(row[3]);
    number.unit = Text(row[4]);
    number.expanded_uncertainty = internal::AsDouble(row[5]);
    number.decision = Text(row[6]);
    runs[run->second].numbers.push_back(std::move(number));
  }
  return runs;
}

}  // namespace arcwheel::store
