// arcwheel toolpath JOB [--wheel summary.json] -o OUTDIR (issue: parallel-grinding toolpath).

#include <filesystem>
#include <optional>
#include <string>

#include "cli/commands.h"
#include "grinding/job.h"
#include "store/records.h"
#include "workflows/record.h"
#include "workflows/steps.h"

namespace arcwheel::cli {

void AddToolpathCommand(CLI::App& app) {
  struct Arguments {
    std::string job;
    std::string wheel;
    std::string output;
    double max_wheel_change_mm = grinding::kDefaultMaxWheelChangeMm;
    std::string wheel_profile = "mean";
    std::string db;
  };
  auto arguments = std::make_shared<Arguments>();
  CLI::App* command = app.add_subcommand(
      "toolpath",
      "parallel-grinding toolpath (CSV, G-code, PMAC) for a job file, with the predicted form error");
  command->add_option("JOB", arguments->job, "job file (JSON, see docs/grinding.md)")->required();
  command->add_option("--wheel", arguments->wheel,
                      "summary.json of the measured wheel (replaces the job's wheel.summary; its arc radius "
                      "replaces the job's nominal wheel.arc_radius_mm)");
  command
      ->add_option(
          "--max-wheel-change-mm", arguments->max_wheel_change_mm,
          "refuse a measured arc radius farther than this from the job's nominal one (a wrong wheel)")
      ->capture_default_str();
  command
      ->add_option("--wheel-profile", arguments->wheel_profile,
                   "with a summary: mean (the per-phase fits' mean radius and mean profile) or model (the "
                   "wheel model's mean radius and profile error p(u), from wheel_map.h5 beside it)")
      ->check(CLI::IsMember({"mean", "model"}))
      ->capture_default_str();
  command->add_option("-o,--output", arguments->output, "output folder")->required();
  AddDbOption(command, arguments->db);
  command->callback([arguments] {
    std::optional<std::filesystem::path> wheel;
    if (!arguments->wheel.empty()) wheel = arguments->wheel;
    workflows::RunRecorded(
        arguments->db,
        [&] {
          (void)workflows::RunToolpathStep(
              arguments->job, wheel, arguments->max_wheel_change_mm, arguments->output,
              arguments->wheel_profile == "model" ? grinding::WheelProfileSource::kModel
                                                  : grinding::WheelProfileSource::kMeanProfile);
        },
        [&] {
          return std::vector<store::StoredRun>{
              store::ToolpathRun(arguments->output, arguments->job, wheel, "toolpath")};
        });
  });
}

}  // namespace arcwheel::cli
