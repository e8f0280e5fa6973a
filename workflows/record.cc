#include "workflows/record.h"

namespace arcwheel::workflows {

std::optional<store::Store> OpenRunStore(const std::string& db_option) {
  const std::string location = store::StoreLocation(db_option);
  if (location.empty()) return std::nullopt;
  return store::Store::OpenForRecording(location);
}

void RunRecorded(const std::string& db_option, const std::function<void()>& body,
                 const std::function<std::vector<store::StoredRun>()>& record) {
  std::optional<store::Store> results = OpenRunStore(db_option);
  body();
  if (!results) return;
  std::vector<store::StoredRun> runs = record();
  results->Record(runs);
}

}  // namespace arcwheel::workflows
