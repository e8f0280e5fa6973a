// arcwheel headcenter: removal-centre location with a six-axis force sensor (method.md D).
//   solve RECORD       the contact centre of one record (and, with a calibration, its machine position
//                      and the offset from the commanded position)
//   calibrate PRESSES  the sensor -> machine planar transform from records pressed at known points
//   moves RECORDS      the repeatability and accuracy tables from records at commanded positions
//   simulate           a simulated record with a known contact point

#include <fmt/core.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include "cli/commands.h"
#include "cli/output.h"
#include "core/atomic_file.h"
#include "core/error.h"
#include "core/json_text.h"
#include "frames/csv_table.h"
#include "frames/force_centre.h"
#include "frames/force_record_io.h"
#include "frames/transform_fit.h"
#include "frames/transform_json.h"

namespace arcwheel::cli {
namespace {

namespace fs = std::filesystem;
constexpr const char* kHeadcenterStage = "headcenter";

struct SolveArgs {
  std::optional<double> z0_mm;
  std::string tare;
  frames::ForceRecordReadOptions units;
  double min_force_fraction = 0.1;
  double min_force_N = 0.0;
};

void AddSolveOptions(CLI::App& command, SolveArgs& args) {
  command.add_option("--z0-mm", args.z0_mm,
                     "platform top above the sensor origin (default: the record's platform_height_mm note)");
  command.add_option("--tare", args.tare, "unloaded record (CSV or HDF5): its mean wrench is subtracted");
  command.add_option("--force-unit", args.units.force_unit, "unit of bare force columns: N or kN");
  command.add_option("--moment-unit", args.units.moment_unit, "unit of bare moment columns: Nmm or Nm");
  command
      .add_option("--min-force-fraction", args.min_force_fraction,
                  "ignore samples with |Fz| below this fraction of the median")
      ->capture_default_str();
  command.add_option("--min-force-N", args.min_force_N, "ignore samples with |Fz| below this")
      ->capture_default_str();
}

// Reads, tares and solves one record.
struct Solved {
  frames::ContactCentre centre;
  double z0_mm = 0.0;
  frames::Wrench tare;
};

frames::Wrench ReadTare(const SolveArgs& args) {
  if (args.tare.empty()) return {};
  return frames::MeanWrench(frames::ReadForceRecord(args.tare, args.units).record);
}

Solved SolveRecord(const std::string& path, const SolveArgs& args, const frames::Wrench& tare) {
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

nlohmann::json TareJson(const SolveArgs& args, const frames::Wrench& tare) {
  return {{"record", args.tare.empty() ? nlohmann::json(nullptr) : nlohmann::json(args.tare)},
          {"force_N", Triple(tare.force_N)},
          {"moment_Nmm", Triple(tare.moment_Nmm)}};
}

frames::Transform ReadCalibration(const std::string& path) {
  return frames::TransformFromJson(ReadJsonFile(path, kHeadcenterStage), path);
}

Eigen::Vector2d ToMachine(const frames::Transform& calibration, const Eigen::Vector2d& sensor) {
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

void AddSolve(CLI::App& headcenter) {
  CLI::App* solve = headcenter.add_subcommand("solve", "contact (removal) centre of one force/torque record");
  struct Args {
    std::string record, calibration, output;
    std::vector<double> commanded;
    SolveArgs solve;
  };
  auto args = std::make_shared<Args>();
  solve->add_option("RECORD", args->record, "CSV or HDF5 record: t_s,Fx_N,Fy_N,Fz_N,Mx_Nmm,My_Nmm,Mz_Nmm")
      ->required();
  AddSolveOptions(*solve, args->solve);
  solve->add_option("--calibration", args->calibration,
                    "sensor -> machine transform JSON (`headcenter calibrate`)");
  solve->add_option("--commanded-mm", args->commanded, "commanded machine X,Y of the head: report the offset")
      ->expected(2)
      ->delimiter(',');
  solve->add_option("-o,--output", args->output, "write the JSON here instead of stdout");
  solve->callback([args] {
    if (!args->commanded.empty() && args->calibration.empty()) {
      throw Error(ErrorCode::kInvalidOption, kHeadcenterStage,
                  "--commanded-mm needs --calibration (the sensor -> machine transform)");
    }
    const Solved solved = SolveRecord(args->record, args->solve, ReadTare(args->solve));
    nlohmann::json out = CentreJson(args->record, solved);
    out["tare"] = TareJson(args->solve, solved.tare);
    const Eigen::Vector2d sigma = solved.centre.SigmaMm();
    std::string summary = fmt::format(
        "{}: centre ({:.4f}, {:.4f}) +- ({:.4f}, {:.4f}) mm in the sensor frame, {} of {} samples\n",
        args->record, solved.centre.centre_mm.x(), solved.centre.centre_mm.y(), sigma.x(), sigma.y(),
        solved.centre.samples_used, solved.centre.samples_total);
    if (!args->calibration.empty()) {
      const frames::Transform calibration = ReadCalibration(args->calibration);
      const Eigen::Vector2d machine = ToMachine(calibration, solved.centre.centre_mm);
      const Eigen::Matrix2d rotation = calibration.scale * calibration.linear.topLeftCorner<2, 2>();
      const Eigen::Matrix2d covariance = rotation * solved.centre.covariance_mm2 * rotation.transpose();
      out["calibration"] = args->calibration;
      out["centre_machine_mm"] = Pair(machine);
      out["centre_machine_sigma_mm"] = Pair(covariance.diagonal().cwiseSqrt());
      summary += fmt::format("  machine position ({:.4f}, {:.4f}) mm\n", machine.x(), machine.y());
      if (!args->commanded.empty()) {
        const Eigen::Vector2d commanded(args->commanded[0], args->commanded[1]);
        out["commanded_mm"] = Pair(commanded);
        out["offset_mm"] = Pair(machine - commanded);
        out["offset_norm_mm"] = (machine - commanded).norm();
        out["offset_convention"] = "offset = actual - commanded, machine frame";
        summary += fmt::format("  removal-centre offset ({:.4f}, {:.4f}) mm\n", (machine - commanded).x(),
                               (machine - commanded).y());
      }
    }
    EmitText(out.dump(2) + "\n", args->output);
    SummariseOnTerminal(summary);
  });
}

void AddCalibrate(CLI::App& headcenter) {
  CLI::App* calibrate =
      headcenter.add_subcommand("calibrate", "sensor -> machine planar transform from pressed points");
  struct Args {
    std::string presses, output;
    SolveArgs solve;
    frames::TransformFitOptions fit;
  };
  auto args = std::make_shared<Args>();
  calibrate->add_option("PRESSES", args->presses, "CSV: record,x_machine_mm,y_machine_mm (>= 3 rows)")
      ->required();
  AddSolveOptions(*calibrate, args->solve);
  calibrate
      ->add_option("--outlier-threshold", args->fit.outlier_threshold, "flag presses beyond this many sigma")
      ->capture_default_str();
  calibrate->add_option("-o,--output", args->output, "write the JSON here instead of stdout");
  calibrate->callback([args] {
    const std::vector<RecordRow> rows = ReadRecordList(args->presses, "x_machine_mm", "y_machine_mm");
    const frames::Wrench tare = ReadTare(args->solve);
    std::vector<frames::PointPair> pairs;
    nlohmann::json presses = nlohmann::json::array();
    for (const RecordRow& row : rows) {
      const Solved solved = SolveRecord(row.path, args->solve, tare);
      pairs.push_back({{solved.centre.centre_mm.x(), solved.centre.centre_mm.y(), 0.0},
                       {row.position_mm.x(), row.position_mm.y(), 0.0}});
      nlohmann::json press = CentreJson(row.path, solved);
      press["machine_mm"] = Pair(row.position_mm);
      presses.push_back(press);
    }
    frames::TransformFit fit;
    try {
      fit = frames::FitTransform(pairs, frames::TransformModel::kRigid2d, args->fit);
    } catch (const Error& error) {
      if (error.code() != ErrorCode::kBadInput && error.code() != ErrorCode::kFitFailed) throw;
      throw Error(error.code(), kHeadcenterStage, fmt::format("'{}': {}", args->presses, error.what()));
    }
    nlohmann::json out = frames::TransformFitToJson(fit);
    out["source_frame"] = "sensor";
    out["target_frame"] = "machine";
    out["presses"] = presses;
    out["tare"] = TareJson(args->solve, tare);
    EmitText(out.dump(2) + "\n", args->output);
    SummariseOnTerminal(
        fmt::format("sensor -> machine: rotation {:.4f} deg, translation ({:.4f}, {:.4f}) mm, rms residual "
                    "{:.4f} mm over {} presses\n",
                    fit.parameters(2) * 180.0 / M_PI, fit.parameters(0), fit.parameters(1),
                    fit.rms_residual_mm, pairs.size()));
  });
}

std::string TablesSummary(const frames::MoveTables& tables) {
  std::string text =
      "repeatability\n  commanded X, Y (mm)     n   mean X, Y (mm)          std X, Y (mm)      max dev "
      "(mm)\n";
  for (const auto& r : tables.repeatability) {
    text += fmt::format("  {:9.4f} {:9.4f}  {:4d}  {:10.4f} {:10.4f}  {:8.4f} {:8.4f}  {:8.4f}\n",
                        r.commanded_mm.x(), r.commanded_mm.y(), r.count, r.mean_mm.x(), r.mean_mm.y(),
                        r.std_mm.x(), r.std_mm.y(), r.max_deviation_mm);
  }
  text += "accuracy (moves from the first position)\n  commanded move (mm)  solved move (mm)  error (mm)\n";
  for (const auto& a : tables.accuracy) {
    text +=
        fmt::format("  {:19.4f}  {:16.4f}  {:10.4f}\n", a.commanded_move_mm, a.solved_move_mm, a.error_mm);
  }
  return text;
}

void AddMoves(CLI::App& headcenter) {
  CLI::App* moves =
      headcenter.add_subcommand("moves", "repeatability and move-accuracy tables from a set of records");
  struct Args {
    std::string records, calibration, output;
    SolveArgs solve;
  };
  auto args = std::make_shared<Args>();
  moves
      ->add_option("RECORDS", args->records,
                   "CSV: record,commanded_x_mm,commanded_y_mm (repeat a position to measure repeatability)")
      ->required();
  AddSolveOptions(*moves, args->solve);
  moves->add_option("--calibration", args->calibration,
                    "sensor -> machine transform JSON: tabulate in machine coordinates");
  moves->add_option("-o,--output", args->output, "write the JSON here instead of stdout");
  moves->callback([args] {
    const std::vector<RecordRow> rows = ReadRecordList(args->records, "commanded_x_mm", "commanded_y_mm");
    const frames::Wrench tare = ReadTare(args->solve);
    const std::optional<frames::Transform> calibration =
        args->calibration.empty() ? std::nullopt : std::optional(ReadCalibration(args->calibration));
    std::vector<frames::MoveSample> samples;
    nlohmann::json records = nlohmann::json::array();
    for (const RecordRow& row : rows) {
      const Solved solved = SolveRecord(row.path, args->solve, tare);
      const Eigen::Vector2d solved_mm =
          calibration ? ToMachine(*calibration, solved.centre.centre_mm) : solved.centre.centre_mm;
      samples.push_back({row.position_mm, solved_mm, row.path});
      nlohmann::json record = CentreJson(row.path, solved);
      record["commanded_mm"] = Pair(row.position_mm);
      record["solved_mm"] = Pair(solved_mm);
      records.push_back(record);
    }
    const frames::MoveTables tables = frames::TabulateMoves(samples);
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
    nlohmann::json out = {{"frame", calibration ? "machine" : "sensor"},
                          {"reference_commanded_mm", Pair(tables.reference_mm)},
                          {"repeatability", repeatability},
                          {"accuracy", accuracy},
                          {"worst_repeatability_mm", tables.worst_repeatability_mm},
                          {"worst_accuracy_mm", tables.worst_accuracy_mm},
                          {"records", records},
                          {"tare", TareJson(args->solve, tare)}};
    EmitText(out.dump(2) + "\n", args->output);
    SummariseOnTerminal(TablesSummary(tables));
  });
}

void AddSimulate(CLI::App& headcenter) {
  CLI::App* simulate = headcenter.add_subcommand(
      "simulate", "write a simulated force/torque record with a known contact point");
  struct Args {
    std::string output;
    std::vector<double> centre = {0.0, 0.0};
    frames::ForceSimulation simulation;
    bool unloaded = false;
    unsigned seed = 1;
  };
  auto args = std::make_shared<Args>();
  simulate->add_option("-o,--output", args->output, "record to write (.csv, or .h5/.hdf5)")->required();
  simulate->add_option("--centre-mm", args->centre, "true contact centre X,Y in the sensor frame")
      ->expected(2)
      ->delimiter(',');
  simulate->add_option("--z0-mm", args->simulation.platform_height_mm, "platform height")
      ->capture_default_str();
  simulate->add_option("--duration-s", args->simulation.duration_s, "record length")->capture_default_str();
  simulate->add_option("--rate-hz", args->simulation.sample_rate_hz, "sample rate")->capture_default_str();
  simulate->add_option("--normal-force-N", args->simulation.normal_force_N, "mean pressing force")
      ->capture_default_str();
  simulate->add_option("--noise", args->simulation.noise_fraction, "noise sigma as a fraction of full scale")
      ->capture_default_str();
  simulate->add_flag("--unloaded", args->unloaded, "write the unloaded (tare) record instead");
  simulate->add_option("--seed", args->seed, "random seed")->capture_default_str();
  simulate->callback([args] {
    frames::ForceSimulation s = args->simulation;
    s.centre_mm = {args->centre[0], args->centre[1]};
    s.tare.force_N = {0.5, -0.3, -40.0};
    s.tare.moment_Nmm = {85.0, -140.0, 6.0};
    std::mt19937 rng(args->seed);
    const frames::ForceRecord record =
        args->unloaded ? frames::SimulateUnloadedRecord(s, rng) : frames::SimulateForceRecord(s, rng);
    const fs::path output = args->output;
    const std::string extension = output.extension().string();
    if (extension == ".h5" || extension == ".hdf5") {
      OutputSet outputs;
      frames::WriteForceRecordHdf5(outputs.Stage(output), record, s.platform_height_mm);
      outputs.Commit();
    } else {
      WriteFileAtomically(
          output,
          frames::ForceRecordCsv(record, {{"platform_height_mm", fmt::format("{}", s.platform_height_mm)},
                                          {"simulated", args->unloaded ? "unloaded" : "loaded"}}));
    }
  });
}

}  // namespace

void AddHeadcenterCommand(CLI::App& app) {
  CLI::App* headcenter =
      app.add_subcommand("headcenter", "removal-centre location with a six-axis force/torque sensor");
  headcenter->require_subcommand(1);
  AddSolve(*headcenter);
  AddCalibrate(*headcenter);
  AddMoves(*headcenter);
  AddSimulate(*headcenter);
}

}  // namespace arcwheel::cli
