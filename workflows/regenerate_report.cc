#include "reports/regenerate_report.h"

#include <fmt/chrono.h>
#include <fmt/core.h>

#include <cmath>
#include <ctime>
#include <nlohmann/json.hpp>

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/hdf5.h"
#include "core/json_text.h"
#include "core/number_format.h"
#include "core/version.h"
#include "reports/format.h"
#include "schema/grid_map.h"
#include "schema/polish_outputs.h"
#include "schema/regenerate_outputs.h"
#include "schema/summary.h"
#include "schema/toolpath_outputs.h"
#include "workflows/regenerate_internal.h"

namespace arcwheel::workflows::regenerate {

using nlohmann::json;
namespace record_key = schema::regenerate::record;
namespace toolpath_key = schema::toolpath::summary;

std::string Mm(const json& v, int decimals) {
  return v.is_number() ? ShowFixed(v.get<double>(), decimals) + " mm" : "n/a";
}
std::string Um(const json& v, int decimals) {
  return v.is_number() ? ShowFixed(v.get<double>(), decimals) + " µm" : "n/a";
}
const json& At(const json& object, std::string_view key) {
  static const json kNull;
  if (!object.is_object()) return kNull;
  const auto it = object.find(key);
  return it == object.end() ? kNull : *it;
}

namespace {

reports::ChainMap ReadChainMap(const fs::path& path, const std::string& caption) {
  const hdf5::File file = hdf5::File::OpenReadOnly(path);
  const schema::grid_map::Location at = schema::grid_map::LocateGridMap(file, kRegenerateStage);
  reports::ChainMap map{
      .caption = caption, .x_mm = {}, .y_mm = {}, .values_um = file.ReadDoubles(at.error_dataset)};
  for (int i = 0; i < at.nx; ++i) map.x_mm.push_back(at.x0_mm + i * at.dx_mm);
  for (int j = 0; j < at.ny; ++j) map.y_mm.push_back(at.y0_mm + j * at.dy_mm);
  return map;
}

struct ChainFiles {
  json wheel;                        // wheel/summary.json
  json toolpath;                     // toolpath/toolpath_summary.json
  json polish;                       // polish/polish_summary.json, null without polishing
  std::optional<json> nominal_path;  // figures of the nominal path's map
};

json MapFigures(const fs::path& path) {
  const hdf5::File file = hdf5::File::OpenReadOnly(path);
  return {{record_key::kPvUm, file.ReadAttributeDouble("/", "pv_um").value_or(NAN)},
          {record_key::kRmsUm, file.ReadAttributeDouble("/", "rms_um").value_or(NAN)}};
}

ChainFiles ReadChainFiles(const fs::path& outdir) {
  ChainFiles f;
  f.wheel = ReadJsonFile(outdir / kWheelStep.id / schema::summary::kFileName, kRegenerateStage);
  f.toolpath = ReadJsonFile(outdir / kToolpathStep.id / kToolpathSummaryFileName, kRegenerateStage);
  const fs::path polish = outdir / kPolishStep.id / schema::polish::kSummaryFileName;
  if (fs::exists(polish)) f.polish = ReadJsonFile(polish, kRegenerateStage);
  const fs::path nominal = outdir / kToolpathStep.id / kNominalPathFileName;
  if (fs::exists(nominal)) f.nominal_path = MapFigures(nominal);
  return f;
}

// The headline numbers kept in OUTDIR/regenerate.json and compared with the previous one.
json Record(const ChainFiles& f) {
  namespace key = schema::summary;
  json record = {
      {record_key::kFinishedUtc, fmt::format("{:%Y-%m-%dT%H:%M:%SZ}", fmt::gmtime(std::time(nullptr)))},
      {record_key::kArcwheelVersion, kVersion},
      {record_key::kWheel,
       {{key::kMeanArcRadiusMm, At(f.wheel, key::kMeanArcRadiusMm)},
        {key::kMeanArcRadiusSigmaMm, At(f.wheel, key::kMeanArcRadiusSigmaMm)},
        {key::kArcRadiusRangeMm, At(f.wheel, key::kArcRadiusRangeMm)},
        {key::kMaxRunoutUm, At(f.wheel, key::kMaxRunoutUm)}}},
      {record_key::kPrediction, At(f.toolpath, toolpath_key::kPrediction)}};
  if (f.nominal_path) record[record_key::kNominalPath] = *f.nominal_path;
  if (!f.polish.is_null()) record[record_key::kPolishAfter] = At(f.polish, schema::polish::summary::kAfter);
  return record;
}

// The regeneration beside OUTDIR finished most recently, if any (its regenerate.json says when).
std::optional<fs::path> FindPreviousBeside(const fs::path& outdir) {
  const fs::path parent = fs::absolute(outdir).parent_path();
  std::optional<fs::path> best;
  std::string best_time;
  std::error_code error;
  for (const fs::directory_entry& entry : fs::directory_iterator(parent, error)) {
    if (!entry.is_directory() || fs::equivalent(entry.path(), outdir, error)) continue;
    const fs::path record = entry.path() / kRecordFileName;
    if (!fs::exists(record)) continue;
    try {
      const std::string time =
          At(ReadJsonFile(record, kRegenerateStage), record_key::kFinishedUtc).get<std::string>();
      if (!best || time > best_time) best = entry.path(), best_time = time;
    } catch (const std::exception&) {
      continue;  // not a record this command wrote
    }
  }
  return best;
}

std::vector<std::string> ChangeRow(const std::string& label, const json& before, const json& now,
                                   const char* unit, int decimals) {
  const auto text = [&](const json& v) {
    return v.is_number() ? ShowFixed(v.get<double>(), decimals) + " " + unit : std::string("n/a");
  };
  const std::string change = before.is_number() && now.is_number()
                                 ? ShowSigned(now.get<double>() - before.get<double>(), decimals) + " " + unit
                                 : "n/a";
  return {label, text(before), text(now), change};
}

std::vector<std::vector<std::string>> Changes(const json& previous, const json& now) {
  namespace key = schema::summary;
  const json &pw = At(previous, record_key::kWheel), &nw = At(now, record_key::kWheel);
  const json &pp = At(previous, record_key::kPrediction), &np = At(now, record_key::kPrediction);
  return {
      ChangeRow("Mean arc radius", At(pw, key::kMeanArcRadiusMm), At(nw, key::kMeanArcRadiusMm), "mm", 5),
      ChangeRow("Its 1-sigma", At(pw, key::kMeanArcRadiusSigmaMm), At(nw, key::kMeanArcRadiusSigmaMm), "mm",
                5),
      ChangeRow("Arc radius range", At(pw, key::kArcRadiusRangeMm), At(nw, key::kArcRadiusRangeMm), "mm", 4),
      ChangeRow("Max runout", At(pw, key::kMaxRunoutUm), At(nw, key::kMaxRunoutUm), "µm", 2),
      ChangeRow("Predicted form error PV", At(pp, toolpath_key::prediction::kPvUm),
                At(np, toolpath_key::prediction::kPvUm), "µm", 3),
      ChangeRow("Predicted form error RMS", At(pp, toolpath_key::prediction::kRmsUm),
                At(np, toolpath_key::prediction::kRmsUm), "µm", 3)};
}

std::vector<reports::KeyValue> WheelRows(const ChainFiles& f) {
  namespace key = schema::summary;
  const json& arc = At(f.toolpath, toolpath_key::kArcRadius);
  std::string verdict = "measured arc radius used by the toolpath";
  if (At(arc, toolpath_key::arc_radius::kNominalMm).is_number()) {
    verdict = fmt::format("accepted: {:+.4f} mm from the job's nominal {} mm, within the limit of ±{} mm",
                          Shown(At(arc, toolpath_key::arc_radius::kDifferenceMm).get<double>()),
                          Shown(At(arc, toolpath_key::arc_radius::kNominalMm).get<double>()),
                          Shown(At(arc, toolpath_key::arc_radius::kMaxChangeMm).get<double>()));
  }
  const json& model = At(f.wheel, key::kModel);
  return {{"Verdict", verdict},
          {"Wheel", At(At(f.wheel, key::kScan), key::scan::kWheelId).is_string()
                        ? At(At(f.wheel, key::kScan), key::scan::kWheelId).get<std::string>()
                        : "no id"},
          {"Mean arc radius", Mm(At(f.wheel, key::kMeanArcRadiusMm), 5) + " (1-sigma " +
                                  Mm(At(f.wheel, key::kMeanArcRadiusSigmaMm), 5) + ")"},
          {"Arc radius range", Mm(At(f.wheel, key::kArcRadiusRangeMm), 4)},
          {"Max runout", Um(At(f.wheel, key::kMaxRunoutUm), 2)},
          {"Noise", Um(At(f.wheel, key::kNoiseSigmaUm), 3)},
          {"Radius varies with phase (model)",
           At(model, key::model::kVariationSignificant).is_boolean()
               ? (At(model, key::model::kVariationSignificant).get<bool>() ? "yes" : "no")
               : "no model"}};
}

std::vector<reports::KeyValue> ToolpathRows(const ChainFiles& f) {
  const json& t = At(f.toolpath, toolpath_key::kToolpath);
  const json& arc = At(f.toolpath, toolpath_key::kArcRadius);
  return {{"Job", At(At(f.toolpath, toolpath_key::kJob), toolpath_key::job::kName).is_string()
                      ? At(At(f.toolpath, toolpath_key::kJob), toolpath_key::job::kName).get<std::string>()
                      : ""},
          {"Wheel", At(f.toolpath, toolpath_key::kWheel).is_string()
                        ? ShowNumbersIn(At(f.toolpath, toolpath_key::kWheel).get<std::string>())
                        : ""},
          {"Arc radius used", Mm(At(arc, toolpath_key::arc_radius::kMeasuredMm), 5) + " measured (1-sigma " +
                                  Mm(At(arc, toolpath_key::arc_radius::kMeasuredSigmaMm), 5) + "); nominal " +
                                  Mm(At(arc, toolpath_key::arc_radius::kNominalMm), 5)},
          {"Control points", reports::FormatJsonValue(At(t, toolpath_key::toolpath::kControlPoints))},
          {"Passes x rows", reports::FormatJsonValue(At(t, toolpath_key::toolpath::kPasses)) + " x " +
                                reports::FormatJsonValue(At(t, toolpath_key::toolpath::kRowsPerPass))},
          {"Smallest gouge gap", Um(At(t, toolpath_key::toolpath::kMinGougeGapUm), 3)},
          {"Files", reports::FormatJsonValue(At(f.toolpath, toolpath_key::kFiles))}};
}

std::vector<reports::KeyValue> PredictionRows(const ChainFiles& f) {
  const json& p = At(f.toolpath, toolpath_key::kPrediction);
  std::vector<reports::KeyValue> rows = {
      {"PV, RMS",
       Um(At(p, toolpath_key::prediction::kPvUm)) + ", " + Um(At(p, toolpath_key::prediction::kRmsUm))},
      {"After piston and tilt: PV, RMS", Um(At(p, toolpath_key::prediction::kPvAfterTiltUm)) + ", " +
                                             Um(At(p, toolpath_key::prediction::kRmsAfterTiltUm))},
      {"Runout ripple PV", Um(At(p, toolpath_key::prediction::kRipplePvUm))},
      {"Arc radius error assumed",
       Mm(At(p, toolpath_key::prediction::kArcRadiusErrorMm), 6) + " (" +
           (At(p, toolpath_key::prediction::kArcRadiusErrorSource).is_string()
                ? At(p, toolpath_key::prediction::kArcRadiusErrorSource).get<std::string>()
                : "") +
           ")"}};
  if (f.nominal_path) {
    rows.push_back({"The nominal wheel's path would print (radius difference alone)",
                    "PV " + Um(At(*f.nominal_path, record_key::kPvUm)) + ", RMS " +
                        Um(At(*f.nominal_path, record_key::kRmsUm)) +
                        ": avoided by the regenerated toolpath"});
  }
  return rows;
}

std::vector<reports::KeyValue> PolishRows(const ChainFiles& f, const std::string& map_file) {
  namespace key = schema::polish::summary;
  const json& s = f.polish;
  return {{"Error map polished", map_file},
          {"Before: PV, RMS", Um(At(At(s, key::kBefore), key::figures::kPvUm), 4) + ", " +
                                  Um(At(At(s, key::kBefore), key::figures::kRmsUm), 4)},
          {"Predicted residual: PV, RMS", Um(At(At(s, key::kAfter), key::figures::kPvUm), 4) + ", " +
                                              Um(At(At(s, key::kAfter), key::figures::kRmsUm), 4)},
          {"Dwell points", reports::FormatJsonValue(At(s, key::kPoints))},
          {"Total dwell", At(s, key::kTotalTimeS).is_number()
                              ? ShowFixed(At(s, key::kTotalTimeS).get<double>(), 1) + " s"
                              : "n/a"},
          {"Program", "polish.mod (ABB RAPID), polishing_path.csv"}};
}

std::string Status(bool ran) {
  return ran ? "done in this run" : "reused: its inputs (SHA-256) are unchanged";
}

}  // namespace

void WriteChainReport(const RegenerateOptions& args, const StepStatus& status, const fs::path& polished_map) {
  const fs::path outdir(args.output);
  const ChainFiles files = ReadChainFiles(outdir);
  json record = Record(files);
  reports::RegenerateReportContent content;
  content.title = "Regeneration after a dressing: " + fs::path(args.job).stem().string();
  content.provenance = {{"Scan", args.scan},
                        {"Part job", args.job},
                        {"Polishing job", args.polish.empty() ? "none" : args.polish},
                        {"Output folder", args.output},
                        {"arcwheel", kVersion}};
  content.steps.push_back({"1. Wheel verdict", Status(status.wheel_ran), WheelRows(files)});
  content.steps.push_back({"2. Toolpath summary", Status(status.toolpath_ran), ToolpathRows(files)});
  content.steps.push_back({"3. Predicted form error", Status(status.toolpath_ran), PredictionRows(files)});
  content.maps.push_back(ReadChainMap(outdir / kToolpathStep.id / kPredictionFileName,
                                      "Predicted form error of the regenerated toolpath (µm)"));
  const fs::path nominal = outdir / kToolpathStep.id / kNominalPathFileName;
  if (fs::exists(nominal)) {
    content.maps.push_back(ReadChainMap(
        nominal, "Form error the nominal wheel's path would print with the measured wheel (µm)"));
  }
  if (status.polish_ran) {
    content.steps.push_back(
        {"4. Polishing plan", Status(*status.polish_ran), PolishRows(files, polished_map.string())});
    content.maps.push_back(ReadChainMap(outdir / kPolishStep.id / schema::polish::kResidualGridFileName,
                                        "Predicted residual after polishing (µm)"));
  } else {
    content.steps.push_back({"4. Polishing plan", "not run: no polishing job (--polish)", {}});
  }
  std::optional<fs::path> previous;
  if (!args.previous.empty()) {
    previous = args.previous;
  } else {
    previous = FindPreviousBeside(outdir);
  }
  if (previous) {
    const fs::path record_path = *previous / kRecordFileName;
    if (!fs::exists(record_path)) {
      throw Error(ErrorCode::kBadInput, kRegenerateStage,
                  fmt::format("--previous '{}' holds no {} (not a finished regeneration)", previous->string(),
                              kRecordFileName));
    }
    const json before = ReadJsonFile(record_path, kRegenerateStage);
    content.previous = fmt::format("{} (finished {})", previous->string(),
                                   At(before, record_key::kFinishedUtc).is_string()
                                       ? At(before, record_key::kFinishedUtc).get<std::string>()
                                       : "?");
    content.changes = Changes(before, record);
    record[record_key::kPrevious] = previous->string();
  }
  const reports::WrittenRegenerateReport written = reports::WriteRegenerateReport(content, outdir);
  WriteFileAtomically(outdir / kRecordFileName, JsonText(record, 2) + "\n");
  fmt::print("step 4/4 report: {}\n                 {}\n", written.html.string(), written.pdf.string());
}

}  // namespace arcwheel::workflows::regenerate
