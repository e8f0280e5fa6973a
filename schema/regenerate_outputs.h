#pragma once
// regenerate.json, the record `arcwheel regenerate` writes last in OUTDIR and reads back from an
// earlier regeneration to compare (workflows/regenerate*.cc): the one place that spells its keys.
// The wheel's figures keep summary.json's names (schema/summary.h), the prediction's those of
// toolpath_summary.json (schema/toolpath_outputs.h), the polish figures polish_summary.json's.

#include <string_view>

namespace arcwheel::schema::regenerate {

inline constexpr std::string_view kRecordFileName = "regenerate.json";
inline constexpr std::string_view kNominalPathFileName = "nominal_path_prediction.h5";

namespace record {
inline constexpr std::string_view kFinishedUtc = "finished_utc";
inline constexpr std::string_view kArcwheelVersion = "arcwheel_version";
inline constexpr std::string_view kWheel = "wheel";               // summary.json's headline numbers
inline constexpr std::string_view kPrediction = "prediction";     // toolpath_summary.json's
inline constexpr std::string_view kNominalPath = "nominal_path";  // pv_um, rms_um of the nominal path
inline constexpr std::string_view kPolishAfter = "polish_after";  // polish_summary.json's "after"
inline constexpr std::string_view kPrevious = "previous";         // the regeneration compared with
inline constexpr std::string_view kPvUm = "pv_um";
inline constexpr std::string_view kRmsUm = "rms_um";
}  // namespace record

}  // namespace arcwheel::schema::regenerate
