#pragma once
// What `history`, `compare` and `db export` ask of the results store (docs/store.md).

#include <filesystem>
#include <nlohmann/json_fwd.hpp>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "reports/history.h"
#include "store/store.h"

namespace arcwheel::store {

// The history of wheel `wheel_id` from its recorded `process` runs (scan time at or after
// `since_s`), as reports::BuildHistory makes it from their folders: the same scans, numbers,
// segments and wear rates, each scan's folder the run's output folder. Throws Error{kBadInput}
// when the store holds no scan of the wheel, or a scan without a readable timestamp.
[[nodiscard]] reports::History HistoryFromStore(Store& store, const std::string& wheel_id,
                                                const std::optional<double>& since_s,
                                                const std::vector<double>& dressing_times_s,
                                                const std::vector<std::string>& dressing_timestamps);

// The output folders of the two scans of wheel `wheel_id` that `compare --wheel` compares: the
// first scan at or after `since_s` (without it, the second-to-last scan) and the last one.
// Throws Error{kBadInput} when the store holds fewer than two such scans.
[[nodiscard]] std::pair<std::filesystem::path, std::filesystem::path> ComparisonFolders(
    Store& store, const std::string& wheel_id, const std::optional<double>& since_s);

// `arcwheel db export`, in the shape SPC tools import: one row per characteristic per run, with
// the run's columns beside the number's (store/schema.h names them). CSV: a header line, then
// the rows; an empty cell for NULL. JSON: {"schema_version": N, "rows": [{...}, ...]}.
[[nodiscard]] std::string ExportCsv(const std::vector<StoredRun>& runs);
[[nodiscard]] nlohmann::json ExportJson(const std::vector<StoredRun>& runs);

}  // namespace arcwheel::store
