#pragma once
// The results store (stage id `store`, docs/store.md): every recorded run of `process`,
// `toolpath` and `polish` (also as `batch` and `regenerate` run them) with its inputs and their
// SHA-256, its options, every headline number with its sigma, its output folder, the arcwheel
// version and the time. SQLite by default (one file), PostgreSQL for a location
// "postgresql://..." (or "postgres://..."). The schema (store/schema.h) is versioned; `Migrate`
// brings an older store to the latest version keeping every row.
//
// A run is recorded after its outputs are committed, all its rows in one transaction: a run that
// fails or is killed records nothing. Two writers at once lose nothing: SQLite waits for the
// other writer (WAL journal, busy timeout, retry), PostgreSQL serialises the transactions.

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "store/schema.h"

namespace arcwheel::store {

namespace internal {
class Database;
}

struct StoredInput {
  std::string role;  // "scan", "job", "wheel", "error_map"
  std::string path;  // absolute
  std::string sha256;
};

struct StoredNumber {
  std::string
      characteristic;  // the output file's key, e.g. "mean_arc_radius_mm", "model.arc_radius_range_mm"
  double value = 0.0;
  std::optional<double> sigma;  // 1 sigma, in `unit`; none for peak-to-valley figures
  std::string unit;
  std::optional<double> expanded_uncertainty;  // U (k = 2), once recorded
  std::string decision;                        // "" until recorded
};

struct StoredRun {
  std::int64_t id = 0;   // assigned by Record
  std::string command;   // "process", "toolpath", "polish"
  std::string via;       // the command the user ran: the same, "batch" or "regenerate"
  std::string wheel_id;  // "" when the run names no wheel
  std::string scan_timestamp;
  std::optional<double> scan_time_s;  // seconds since 1970 UTC of scan_timestamp
  std::string recorded_at;            // ISO 8601 UTC; set by Record when empty
  std::string arcwheel_version;       // set by Record when empty
  std::string output_folder;          // absolute
  std::string options;                // JSON text
  std::string host;                   // set by Record when empty
  std::vector<StoredInput> inputs;
  std::vector<StoredNumber> numbers;
  [[nodiscard]] const StoredNumber* Number(const std::string& characteristic) const;
};

struct RunFilter {
  std::string wheel_id;           // empty: every wheel
  std::string command;            // empty: every command
  std::optional<double> since_s;  // scans at or after this time (seconds since 1970 UTC)
};

// The store a command records into: `option` (`--db`) when not empty, else the environment
// variable ARCWHEEL_DB, else "" (no store).
[[nodiscard]] std::string StoreLocation(const std::string& option);

// "YYYY-MM-DD" (midnight UTC) or an ISO 8601 date-time as reports::ParseTimestamp_s reads it, in
// seconds since 1970 UTC. Throws Error{kInvalidOption} naming `option`.
[[nodiscard]] double ParseSince_s(const std::string& text, const std::string& option);

class Store {
 public:
  // Connects to `location` (a file path or a postgresql:// URL); creates nothing but an empty
  // SQLite file. Throws Error{kIo, "store"} naming the location when it cannot be reached.
  [[nodiscard]] static Store Open(const std::string& location);
  // Open, then make sure runs can be recorded: an empty store gets the latest schema; a store at an
  // older version is refused (Error{kBadInput}: run `arcwheel db migrate`), as is a newer one.
  // Commands call this before they write any output.
  [[nodiscard]] static Store OpenForRecording(const std::string& location);

  Store(Store&&) noexcept;
  Store& operator=(Store&&) noexcept;
  ~Store();

  // The file, or the URL without its password.
  [[nodiscard]] const std::string& Name() const;
  // The schema version the store is at; 0 when it holds no schema.
  [[nodiscard]] int Version();
  // Creates the schema at `version` (1 .. kLatestVersion) in an empty store; a store at the
  // latest version already is left as it is. Throws Error{kBadInput} for a store at another version.
  void Init(int version = schema::store::kLatestVersion);
  // Applies each migration from the store's version to the latest in one transaction: every row
  // is kept. Returns {from, to}. Throws Error{kBadInput} for an empty store or a newer one.
  std::pair<int, int> Migrate();
  // Records the runs in one transaction and sets their ids; all or none.
  void Record(std::vector<StoredRun>& runs);
  // Whether a `command` run into `output_folder` (absolute) whose input of role `role` has
  // `sha256` is recorded.
  [[nodiscard]] bool HasRun(const std::string& command, const std::string& output_folder,
                            const std::string& role, const std::string& sha256);
  // The recorded runs that pass the filter, in the order of their scan time, then of recording.
  [[nodiscard]] std::vector<StoredRun> Runs(const RunFilter& filter = {});

 private:
  explicit Store(std::unique_ptr<internal::Database> database);
  void RequireVersion(int version);
  std::unique_ptr<internal::Database> database_;
};

}  // namespace arcwheel::store
