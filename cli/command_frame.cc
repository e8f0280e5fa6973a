// arcwheel frame: the three-point workpiece frame (method.md E), and
// arcwheel frame pmac: the PMAC/UMAC axis definitions that realise a frame on the controller.

#include <fmt/core.h>
#include <unistd.h>

#include <array>
#include <fstream>
#include <memory>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "cli/commands.h"
#include "cli/output.h"
#include "core/atomic_file.h"
#include "core/error.h"
#include "core/json_text.h"
#include "frames/three_point_frame.h"
#include "frames/transform_json.h"

namespace arcwheel::cli {
namespace {

constexpr const char* kFrameStage = "frame";

struct PmacArgs {
  std::vector<double> counts_per_mm;
  std::vector<int> motors = {1, 2, 3};
  int coordinate_system = 1;
  int decimals = 6;
};

void AddPmacOptions(CLI::App& command, PmacArgs& pmac, bool required) {
  CLI::Option* counts = command
                            .add_option("--counts-per-mm", pmac.counts_per_mm,
                                        "motor counts per mm of machine X, Y, Z (sign = direction)")
                            ->expected(3)
                            ->delimiter(',');
  if (required) counts->required();
  command.add_option("--motors", pmac.motors, "motor numbers of machine X, Y, Z")
      ->expected(3)
      ->delimiter(',')
      ->capture_default_str();
  command.add_option("--coordinate-system", pmac.coordinate_system, "PMAC coordinate system &n")
      ->capture_default_str();
  command.add_option("--pmac-decimals", pmac.decimals, "digits after the point of the coefficients")
      ->capture_default_str();
}

std::vector<std::string> PmacLines(const frames::Transform& machine_from_workpiece, const PmacArgs& pmac) {
  frames::PmacAxisOptions options{.coordinate_system = pmac.coordinate_system, .decimals = pmac.decimals};
  for (int k = 0; k < 3; ++k) {
    options.motors[k] = pmac.motors[k];
    options.counts_per_mm[k] = pmac.counts_per_mm[k];
  }
  return frames::PmacAxisDefinitions(machine_from_workpiece, options);
}

Eigen::Vector3d Point(const std::vector<double>& values) { return {values[0], values[1], values[2]}; }

nlohmann::json FrameJson(const frames::WorkpieceFrame& frame, const std::array<Eigen::Vector3d, 3>& probes) {
  const frames::Transform forward = frame.MachineFromWorkpiece();
  // The top level is the workpiece -> machine transform, so the file works with `transform apply`.
  nlohmann::json out = frames::TransformToJson(forward);
  out["source_frame"] = "workpiece";
  out["target_frame"] = "machine";
  const auto vector = [](const Eigen::Vector3d& v) { return nlohmann::json{v.x(), v.y(), v.z()}; };
  out["frame"] = {{"origin_mm", vector(frame.origin_mm)},
                  {"x_axis", vector(frame.axes.col(0))},
                  {"y_axis", vector(frame.axes.col(1))},
                  {"z_axis", vector(frame.axes.col(2))},
                  {"angle_p2_p3_deg", frame.angle_p2_p3_deg}};
  out["probes_mm"] = {
      {"origin", vector(probes[0])}, {"x_point", vector(probes[1])}, {"xy_point", vector(probes[2])}};
  out["machine_from_workpiece"] = frames::TransformToJson(forward);
  out["workpiece_from_machine"] = frames::TransformToJson(frame.WorkpieceFromMachine());
  out["formulas"] = "machine = P1 + [i j k] * workpiece; workpiece = [i j k]^T * (machine - P1)";
  return out;
}

void AddPmac(CLI::App& frame) {
  CLI::App* pmac =
      frame.add_subcommand("pmac", "PMAC/UMAC axis definitions #n->AnX+BnY+CnZ+Dn for a frame JSON");
  struct Args {
    std::string frame_json, output;
    PmacArgs pmac;
  };
  auto args = std::make_shared<Args>();
  pmac->add_option("FRAME", args->frame_json,
                   "JSON from `arcwheel frame` (or any workpiece -> machine transform)")
      ->required();
  AddPmacOptions(*pmac, args->pmac, true);
  pmac->add_option("-o,--output", args->output, "write the lines here instead of stdout");
  pmac->callback([args] {
    const nlohmann::json json = ReadJsonFile(args->frame_json, "frame.pmac");
    const frames::Transform transform = frames::TransformFromJson(json, args->frame_json);
    std::string text =
        fmt::format("; workpiece frame from {} (counts per mm {}, {}, {})\n", args->frame_json,
                    args->pmac.counts_per_mm[0], args->pmac.counts_per_mm[1], args->pmac.counts_per_mm[2]);
    for (const std::string& line : PmacLines(transform, args->pmac)) text += line + "\n";
    EmitText(text, args->output);
  });
}

}  // namespace

void AddFrameCommand(CLI::App& app) {
  CLI::App* frame =
      app.add_subcommand("frame", "three-point workpiece frame from probed points (JSON on stdout)");
  struct Args {
    std::vector<double> origin, x_point, xy_point;
    frames::ThreePointFrameOptions options;
    PmacArgs pmac;
    std::string output;
  };
  auto args = std::make_shared<Args>();
  frame->add_option("--origin", args->origin, "P1: the workpiece origin, machine X,Y,Z in mm")
      ->expected(3)
      ->delimiter(',');
  frame->add_option("--x-point", args->x_point, "P2: a point on the workpiece +X axis")
      ->expected(3)
      ->delimiter(',');
  frame->add_option("--xy-point", args->xy_point, "P3: a point in the workpiece XY plane, +Y side")
      ->expected(3)
      ->delimiter(',');
  frame->add_option("--min-separation-mm", args->options.min_separation_mm, "refuse points closer than this")
      ->capture_default_str();
  frame
      ->add_option("--min-angle-deg", args->options.min_angle_deg,
                   "refuse P2, P3 closer to collinear than this")
      ->capture_default_str();
  AddPmacOptions(*frame, args->pmac, false);
  frame->add_option("-o,--output", args->output, "write the JSON here instead of stdout");
  frame->footer(
      "With --counts-per-mm the JSON also holds \"pmac_axis_definitions\". `arcwheel frame pmac FRAME.json`\n"
      "prints them alone. Apply the frame to a file with `arcwheel transform apply FRAME.json FILE`.");
  AddPmac(*frame);
  frame->callback([frame, args] {
    if (frame->got_subcommand("pmac")) return;
    for (const auto& [values, name] : {std::pair{&args->origin, "--origin"},
                                       {&args->x_point, "--x-point"},
                                       {&args->xy_point, "--xy-point"}}) {
      if (values->size() != 3)
        throw Error(ErrorCode::kInvalidOption, kFrameStage, fmt::format("{} X,Y,Z is required", name));
    }
    const std::array<Eigen::Vector3d, 3> probes = {Point(args->origin), Point(args->x_point),
                                                   Point(args->xy_point)};
    const frames::WorkpieceFrame result =
        frames::ThreePointFrame(probes[0], probes[1], probes[2], args->options);
    nlohmann::json out = FrameJson(result, probes);
    std::string summary =
        fmt::format("workpiece frame: origin ({:.6f}, {:.6f}, {:.6f}) mm, angle P2-P1-P3 {:.3f} deg\n",
                    result.origin_mm.x(), result.origin_mm.y(), result.origin_mm.z(), result.angle_p2_p3_deg);
    if (!args->pmac.counts_per_mm.empty()) {
      const std::vector<std::string> lines = PmacLines(result.MachineFromWorkpiece(), args->pmac);
      out["pmac_axis_definitions"] = lines;
      for (const std::string& line : lines) summary += "  " + line + "\n";
    }
    EmitText(JsonText(out, 2) + "\n", args->output);
    if (::isatty(STDERR_FILENO)) fmt::print(stderr, "{}", summary);
  });
}

}  // namespace arcwheel::cli
