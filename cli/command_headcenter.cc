// arcwheel headcenter: removal-centre location with a six-axis force sensor (method.md D).
//   solve RECORD       the contact centre of one record (and, with a calibration, its machine position
//                      and the offset from the commanded position)
//   calibrate PRESSES  the sensor -> machine planar transform from records pressed at known points
//   moves RECORDS      the repeatability and accuracy tables from records at commanded positions
//   simulate           a simulated record with a known contact point

#include <fmt/core.h>

#include <cmath>
#include <filesystem>
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
#include "core/number_format.h"
#include "frames/force_centre.h"
#include "frames/force_record_io.h"
#include "workflows/headcenter.h"

namespace arcwheel::cli {
namespace {

namespace fs = std::filesystem;
using workflows::RecordSolveOptions;

void AddSolveOptions(CLI::App& command, RecordSolveOptions& args) {
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

void AddSolve(CLI::App& headcenter) {
  CLI::App* solve = headcenter.add_subcommand("solve", "contact (removal) centre of one force/torque record");
  struct Args {
    std::string record, calibration, output;
    std::vector<double> commanded;
    RecordSolveOptions solve;
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
    const std::optional<Eigen::Vector2d> commanded =
        args->commanded.empty() ? std::nullopt
                                : std::optional(Eigen::Vector2d(args->commanded[0], args->commanded[1]));
    const workflows::HeadcenterSolve solved =
        workflows::SolveHeadcenterRecord(args->record, args->calibration, commanded, args->solve);
    const Eigen::Vector2d sigma = solved.centre.SigmaMm();
    std::string summary = fmt::format(
        "{}: centre ({:.4f}, {:.4f}) +- ({:.4f}, {:.4f}) mm in the sensor frame, {} of {} samples\n",
        args->record, Shown(solved.centre.centre_mm.x()), Shown(solved.centre.centre_mm.y()),
        Shown(sigma.x()), Shown(sigma.y()), solved.centre.samples_used, solved.centre.samples_total);
    if (solved.centre_machine_mm) {
      summary += fmt::format("  machine position ({:.4f}, {:.4f}) mm\n", Shown(solved.centre_machine_mm->x()),
                             Shown(solved.centre_machine_mm->y()));
    }
    if (solved.offset_mm) {
      summary += fmt::format("  removal-centre offset ({:.4f}, {:.4f}) mm\n", Shown(solved.offset_mm->x()),
                             Shown(solved.offset_mm->y()));
    }
    EmitText(JsonText(solved.json, 2) + "\n", args->output);
    SummariseOnTerminal(summary);
  });
}

void AddCalibrate(CLI::App& headcenter) {
  CLI::App* calibrate =
      headcenter.add_subcommand("calibrate", "sensor -> machine planar transform from pressed points");
  struct Args {
    std::string presses, output;
    RecordSolveOptions solve;
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
    const workflows::HeadcenterCalibration result =
        workflows::CalibrateHeadcenter(args->presses, args->solve, args->fit);
    const frames::TransformFit& fit = result.fit;
    EmitText(JsonText(result.json, 2) + "\n", args->output);
    SummariseOnTerminal(
        fmt::format("sensor -> machine: rotation {:.4f} deg, translation ({:.4f}, {:.4f}) mm, rms residual "
                    "{:.4f} mm over {} presses\n",
                    Shown(fit.parameters(2) * 180.0 / M_PI), Shown(fit.parameters(0)),
                    Shown(fit.parameters(1)), Shown(fit.rms_residual_mm), result.presses));
  });
}

std::string TablesSummary(const frames::MoveTables& tables) {
  std::string text =
      "repeatability\n  commanded X, Y (mm)     n   mean X, Y (mm)          std X, Y (mm)      max dev "
      "(mm)\n";
  for (const auto& r : tables.repeatability) {
    text += fmt::format("  {:9.4f} {:9.4f}  {:4d}  {:10.4f} {:10.4f}  {:8.4f} {:8.4f}  {:8.4f}\n",
                        Shown(r.commanded_mm.x()), Shown(r.commanded_mm.y()), r.count, Shown(r.mean_mm.x()),
                        Shown(r.mean_mm.y()), Shown(r.std_mm.x()), Shown(r.std_mm.y()),
                        Shown(r.max_deviation_mm));
  }
  text += "accuracy (moves from the first position)\n  commanded move (mm)  solved move (mm)  error (mm)\n";
  for (const auto& a : tables.accuracy) {
    text += fmt::format("  {:19.4f}  {:16.4f}  {:10.4f}\n", Shown(a.commanded_move_mm),
                        Shown(a.solved_move_mm), Shown(a.error_mm));
  }
  return text;
}

void AddMoves(CLI::App& headcenter) {
  CLI::App* moves =
      headcenter.add_subcommand("moves", "repeatability and move-accuracy tables from a set of records");
  struct Args {
    std::string records, calibration, output;
    RecordSolveOptions solve;
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
    const workflows::HeadcenterMoves result =
        workflows::TabulateHeadcenterMoves(args->records, args->calibration, args->solve);
    EmitText(JsonText(result.json, 2) + "\n", args->output);
    SummariseOnTerminal(TablesSummary(result.tables));
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
