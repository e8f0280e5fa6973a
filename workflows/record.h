#pragma once
// Recording a command's run in the results store (store/store.h, docs/store.md): the store is
// opened (and an empty one given its schema) before the command writes anything, so that an
// unreachable store fails the run with no output; the runs are recorded after every output is
// committed, in one transaction, so that a failed or killed run records nothing.

#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "store/store.h"

namespace arcwheel::workflows {

// The store of `--db` (`db_option`), else of ARCWHEEL_DB, opened for recording; empty when
// neither names one. Throws Error{kIo, "store"} naming it when it cannot be reached.
[[nodiscard]] std::optional<store::Store> OpenRunStore(const std::string& db_option);

// Opens the store (OpenRunStore), runs `body`, which writes the command's outputs, then records
// what `record` returns (read from those outputs). Without a store, only runs `body`. An error of
// `body` propagates and records nothing.
void RunRecorded(const std::string& db_option, const std::function<void()>& body,
                 const std::function<std::vector<store::StoredRun>()>& record);

}  // namespace arcwheel::workflows
