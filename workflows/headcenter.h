#pragma once
// `arcwheel headcenter solve | calibrate | moves`: the removal centre of a polishing head from
// six-axis force/torque records (method.md D), as library calls that read the records, solve
// them and return the JSON the command writes (docs/frames.md).

#include <Eigen/Core>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>

#include "frames/force_centre.h"
#include "frames/force_record_io.h"
#include "frames/transform_fit.h"

namespace arcwheel::workflows {

// How each record is read and solved.
struct RecordSolveOptions {
  // Platform top above the sensor origin (mm); unset: the record's platform_height_mm note.
  std::optional<double> z0_mm;
  std::string tare;  // unloaded record whose mean wrench is subtracted; empty: none
  frames::ForceRecordReadOptions units;
  double min_force_fraction = 0.1;  // ignore samples with |Fz| below this fraction of the median
  double min_force_N = 0.0;         // ignore samples with |Fz| below this
};

struct HeadcenterSolve {
  nlohmann::json json;  // what `headcenter solve` writes
  frames::ContactCentre centre;
  std::optional<Eigen::Vector2d> centre_machine_mm;  // with a calibration
  std::optional<Eigen::Vector2d> offset_mm;          // actual - commanded, with commanded_mm
};

// The contact centre of one record; with `calibration` (a sensor -> machine transform JSON) its
// machine position, and with `commanded_mm` too the offset from it. Throws Error.
[[nodiscard]] HeadcenterSolve SolveHeadcenterRecord(const std::string& record, const std::string& calibration,
                                                    const std::optional<Eigen::Vector2d>& commanded_mm,
                                                    const RecordSolveOptions& options);

struct HeadcenterCalibration {
  nlohmann::json json;  // what `headcenter calibrate` writes
  frames::TransformFit fit;
  size_t presses = 0;
};

// The sensor -> machine planar transform from the records a CSV list names
// (record,x_machine_mm,y_machine_mm; paths relative to the list). Throws Error.
[[nodiscard]] HeadcenterCalibration CalibrateHeadcenter(const std::string& presses,
                                                        const RecordSolveOptions& options,
                                                        const frames::TransformFitOptions& fit_options);

struct HeadcenterMoves {
  nlohmann::json json;  // what `headcenter moves` writes
  frames::MoveTables tables;
};

// Repeatability and move-accuracy tables from the records a CSV list names
// (record,commanded_x_mm,commanded_y_mm), in machine coordinates with `calibration`. Throws Error.
[[nodiscard]] HeadcenterMoves TabulateHeadcenterMoves(const std::string& records,
                                                      const std::string& calibration,
                                                      const RecordSolveOptions& options);

}  // namespace arcwheel::workflows
