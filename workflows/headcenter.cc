#include "workflows/headcenter.h"

#include <fmt/core.h>

#include <filesystem>
#include <vector>

#include "core/error.h"
#include "core/json_text.h"
#include "frames/csv_table.h"
#include "frames/transform_json.h"

namespace arcwheel::workflows {
namespace {

namespace fs = std::filesystem;
constexpr const char* kHeadcenterStage = "headcenter";

// Reads, tares and solves one record.
struct Solved {
  frames::ContactCentre centre;
  double z0_mm = 0.0;
  frames::Wrench tare;
};

frames::Wrench ReadTare(const RecordSolveOptions& args) {
  if (args.tare.empty()) return {};
  return frames::MeanWrench(frames::ReadForceRecord(args.tare, args.units).record);
}

Solved SolveRecord(const std::string& path, const RecordSolveOptions& args, const frames::Wrench& tare) {
  const frames::ForceRecordFile file = frames::ReadForceRecord(path, args.units);
  const std::optional<double> z0 = args.z0_mm ? args.z0_mm : file.platform_height_mm;
  if (!z0) {
    throw Error(ErrorCode::kInvalidOption, kHeadcenterStage,
                fmt::format("'{}' has no platform_height_mm note: give --z0-mm", path));
  }
  Solved solved;
  solved.z0_mm = *z0;
  solved.tare = tare;
  solved.centre = frames::SolveContactCentre(frames::Tare(file.record, tare),
                                             {.platform_height_mm = *z0,
                                              .min_normal_force_fraction = args.min_force_fraction,
                                              .min_normal_force_N = args.min_force_N});
  return solved;
}

nlohmann::json Pair(const Eigen::Vector2d& v) { return {v.x(), v.y()}; }
nlohmann::json Triple(const Eigen::Vector3d& v) { return {v.x(), v.y(), v.z()}; }

nlohmann::json CentreJson(const std::string& path, const Solved& solved) {
  const frames::ContactCentre& c = solved.centre;
  return {{"record", path},
          {"platform_height_mm", solved.z0_mm},
          {"centre_sensor_mm", Pair(c.centre_mm)},
          {"centre_sigma_mm", Pair(c.SigmaMm())},
          {"samples_total", c.samples_total},
          {"samples_used", c.samples_used},
          {"normal_force_threshold_N", c.normal_force_threshold_N},
          {"mean_normal_force_N", c.mean_normal_force_N},
          {"rms_moment_residual_Nmm", Pair(c.rms_moment_residual_Nmm)},
          {"friction_couple_Nmm", c.friction_couple_Nmm}};
}

nlohmann::json TareJson(const RecordSolveOptions& args, const frames::Wrench& tare) {
  return {{"record", args.tare.empty() ? nlohmann::json(nullptr) : nlohmann::json(args.tare)},
          {"force_N", Triple(tare.force_N)},
          {"moment_Nmm", Triple(tare.moment_Nmm)}};
}

frames::Transform ReadCalibration(const std::string& path) {
  return frames::TransformFromJson(ReadJsonFile(path, kHeadcenterStage), path);
}

Eigen::Vector2d MachineFromSensor(const frames::Transform& calibration, const Eigen::Vector2d& sensor) {
  return calibration.ApplyToPoint({sensor.x(), sensor.y(), 0.0}).head<2>();
}

// A list of records with two numeric columns; record paths are relative to the list's folder.
struct RecordRow {
  std::string path;
  Eigen::Vector2d position_mm;
};

std::vector<RecordRow> ReadRecordList(const std::string& list, const char* x_name, const char* y_name) {
  const frames::CsvTable table = frames::ReadCsvTable(list, kHeadcenterStage);
  const size_t record = table.Require("record", kHeadcenterStage),
               x = table.Require(x_name, kHeadcenterStage), y = table.Require(y_name, kHeadcenterStage);
  std::vector<RecordRow> rows;
  for (size_t row = 0; row < table.cells.size(); ++row) {
    fs::path path = table.cells[row][record];
    if (path.is_relative()) path = fs::path(list).parent_path() / path;
    rows.push_back(
        {path.string(), {table.Number(row, x, kHeadcenterStage), table.Number(row, y, kHeadcenterStage)}});
  }
  return rows;
}

}  // namespace

HeadcenterSolve SolveHeadcenterRecord(const std::string& record, const std::string& calibration_path,
                                      const std::optional<Eigen::Vector2d>& commanded_mm,
                                      const RecordSolveOptions& options) {
  if (commanded_mm && calibration_path.empty()) {
    throw Error(ErrorCode::kInvalidOption, kHeadcenterStage,
                "--commanded-mm needs --calibration (the sensor -> machine transform)");
  }
  const Solved solved = SolveRecord(record, options, ReadTare(options));
  HeadcenterSolve result;
  result.json = CentreJson(record, solved);
  result.centre = solved.centre;
  nlohmann::json& out = result.json;
  out["tare"] = TareJson(options, solved.tare);
  if (!calibration_path.empty()) {
    const frames::Transform calibration = ReadCalibration(calibration_path);
    const Eigen::Vector2d machine = MachineFromSensor(calibration, solved.centre.centre_mm);
    const Eigen::Matrix2d rotation = calibration.scale * calibration.linear.topLeftCorner<2, 2>();
    const Eigen::Matrix2d covariance = rotation * solved.centre.covariance_mm2 * rotation.transpose();
    out["calibration"] = calibration_path;
    out["centre_machine_mm"] = Pair(machine);
    out["centre_machine_sigma_mm"] = Pair(covariance.diagonal().cwiseSqrt());
    result.centre_machine_mm = machine;
    if (commanded_mm) {
      out["commanded_mm"] = Pair(*commanded_mm);
      out["offset_mm"] = Pair(machine - *commanded_mm);
      out["offset_norm_mm"] = (machine - *commanded_mm).norm();
      out["offset_convention"] = "offset = actual - commanded, machine frame";
      result.offset_mm = machine - *commanded_mm;
    }
  }
  return result;
}

HeadcenterCalibration CalibrateHeadcenter(const std::string& presses_path, const RecordSolveOptions& options,
                                          const frames::TransformFitOptions& fit_options) {
  const std::vector<RecordRow> rows = ReadRecordList(presses_path, "x_machine_mm", "y_machine_mm");
  const frames::Wrench tare = ReadTare(options);
  std::vector<frames::PointPair> pairs;
  nlohmann::json presses = nlohmann::json::array();
  for (const RecordRow& row : rows) {
    const Solved solved = SolveRecord(row.path, options, tare);
    pairs.push_back({{solved.centre.centre_mm.x(), solved.centre.centre_mm.y(), 0.0},
                     {row.position_mm.x(), row.position_mm.y(), 0.0}});
    nlohmann::json press = CentreJson(row.path, solved);
    press["machine_mm"] = Pair(row.position_mm);
    presses.push_back(press);
  }
  HeadcenterCalibration result;
  try {
    result.fit = frames::FitTransform(pairs, frames::TransformModel::kRigid2d, fit_options);
  } catch (const Error& error) {
    if (error.code() != ErrorCode::kBadInput && error.code() != ErrorCode::kFitFailed) throw;
    throw Error(error.code(), kHeadcenterStage, fmt::format("'{}': {}", presses_path, error.what()));
  }
  result.presses = pairs.size();
  nlohmann::json& out = result.json;
  out = frames::TransformFitToJson(result.fit);
  out["source_frame"] = "sensor";
  out["target_frame"] = "machine";
  out["presses"] = presses;
  out["tare"] = TareJson(options, tare);
  return result;
}

HeadcenterMoves TabulateHeadcenterMoves(const std::string& records_path, const std::string& calibration_path,
                                        const RecordSolveOptions& options) {
  const std::vector<RecordRow> rows = ReadRecordList(records_path, "commanded_x_mm", "commanded_y_mm");
  const frames::Wrench tare = ReadTare(options);
  const std::optional<frames::Transform> calibration =
      calibration_path.empty() ? std::nullopt : std::optional(ReadCalibration(calibration_path));
  std::vector<frames::MoveSample> samples;
  nlohmann::json records = nlohmann::json::array();
  for (const RecordRow& row : rows) {
    const Solved solved = SolveRecord(row.path, options, tare);
    const Eigen::Vector2d solved_mm =
        calibration ? MachineFromSensor(*calibration, solved.centre.centre_mm) : solved.centre.centre_mm;
    samples.push_back({row.position_mm, solved_mm, row.path});
    nlohmann::json record = CentreJson(row.path, solved);
    record["commanded_mm"] = Pair(row.position_mm);
    record["solved_mm"] = Pair(solved_mm);
    records.push_back(record);
  }
  HeadcenterMoves result{.json = {}, .tables = frames::TabulateMoves(samples)};
  const frames::MoveTables& tables = result.tables;
  nlohmann::json repeatability = nlohmann::json::array(), accuracy = nlohmann::json::array();
  for (const auto& r : tables.repeatability) {
    repeatability.push_back({{"commanded_mm", Pair(r.commanded_mm)},
                             {"count", r.count},
                             {"mean_mm", Pair(r.mean_mm)},
                             {"std_mm", Pair(r.std_mm)},
                             {"max_deviation_mm", r.max_deviation_mm}});
  }
  for (const auto& a : tables.accuracy) {
    accuracy.push_back({{"commanded_mm", Pair(a.commanded_mm)},
                        {"commanded_move_mm", a.commanded_move_mm},
                        {"solved_move_mm", a.solved_move_mm},
                        {"error_mm", a.error_mm}});
  }
  result.json = {{"frame", calibration ? "machine" : "sensor"},
                 {"reference_commanded_mm", Pair(tables.reference_mm)},
                 {"repeatability", repeatability},
                 {"accuracy", accuracy},
                 {"worst_repeatability_mm", tables.worst_repeatability_mm},
                 {"worst_accuracy_mm", tables.worst_accuracy_mm},
                 {"records", records},
                 {"tare", TareJson(options, tare)}};
  return result;
}

}  // namespace arcwheel::workflows
