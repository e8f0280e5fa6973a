#pragma once
// Removal-centre location with a six-axis force/torque sensor (method.md D).
//
// The polishing pad presses on a platform of height z0 (its top face, in the sensor frame) mounted on
// the sensor. The sensor reports the wrench applied to the platform about the sensor origin; for a
// contact whose pressure centre is p = (x0, y0, z0):
//   M = p x F:   Mx = y0 Fz - z0 Fy,   My = z0 Fx - x0 Fz,   Mz = x0 Fy - y0 Fx + (pad friction couple).
// The friction of the spinning pad is distributed over the contact but acts in the plane z = z0, so
// it enters Mx and My only through the z0 terms; its couple about the normal enters Mz alone, which
// is therefore not used for the solve (it is reported as a diagnostic).
// With z0 known, (x0, y0) follow from the Mx and My equations in linear least squares over the
// record:   y0 = sum Fz (Mx + z0 Fy) / sum Fz^2,   x0 = sum Fz (z0 Fx - My) / sum Fz^2.
// Samples weigh in with Fz^2, so those with little normal force barely count; below a threshold they
// are left out altogether.

#include <Eigen/Core>
#include <random>
#include <span>
#include <string>
#include <vector>

namespace arcwheel::frames {

// A six-axis record in SI-with-millimetres units, as every reader returns it.
struct ForceRecord {
  std::vector<double> t_s;
  std::vector<double> fx_N, fy_N, fz_N;
  std::vector<double> mx_Nmm, my_Nmm, mz_Nmm;
  std::string source;  // file name or description, for messages
  [[nodiscard]] size_t size() const { return t_s.size(); }
};

struct Wrench {
  Eigen::Vector3d force_N = Eigen::Vector3d::Zero();
  Eigen::Vector3d moment_Nmm = Eigen::Vector3d::Zero();
};

// Throws Error{kBadInput, "frames.force_record"} naming the record if the channels differ in length,
// the record is empty, a value is not finite (naming the channel and sample) or t_s is not strictly
// increasing.
void ValidateForceRecord(const ForceRecord& record);

// The tare: the mean wrench of an unloaded record (platform on the sensor, pad not touching). It
// holds the sensor's zero offset and the platform's weight and the moment of its centre of mass,
// which stay constant as long as the sensor is not tilted.
[[nodiscard]] Wrench MeanWrench(const ForceRecord& unloaded);
// `record` minus `tare`, channel by channel.
[[nodiscard]] ForceRecord Tare(const ForceRecord& record, const Wrench& tare);

struct ContactSolveOptions {
  // Height of the platform's top face above the sensor origin, in mm. Finite.
  double platform_height_mm = 0.0;
  // Samples with |Fz| below this fraction of the record's median |Fz| are left out. In [0, 1).
  double min_normal_force_fraction = 0.1;
  // ... and those with |Fz| below this absolute value, in N. >= 0.
  double min_normal_force_N = 0.0;
  // Empty when valid, else one line per violation with its value, named by the flag of
  // `arcwheel headcenter`: "--min-force-N = -1 violates >= 0".
  [[nodiscard]] std::vector<std::string> Problems() const;
};

struct ContactCentre {
  Eigen::Vector2d centre_mm = Eigen::Vector2d::Zero();  // (x0, y0) in the sensor frame
  // Covariance of centre_mm from the moment-equation residuals (independent, equal-variance
  // residuals assumed: slow drifts or periodic disturbances make it optimistic).
  Eigen::Matrix2d covariance_mm2 = Eigen::Matrix2d::Zero();
  int samples_total = 0;
  int samples_used = 0;
  double normal_force_threshold_N = 0.0;
  double mean_normal_force_N = 0.0;  // mean Fz over the samples used (negative when pressing down)
  Eigen::Vector2d rms_moment_residual_Nmm = Eigen::Vector2d::Zero();  // of the Mx and My equations
  double friction_couple_Nmm = 0.0;  // mean of Mz - (x0 Fy - y0 Fx): the pad's own couple
  [[nodiscard]] Eigen::Vector2d SigmaMm() const { return covariance_mm2.diagonal().cwiseSqrt(); }
};

// Solves (x0, y0) from a tared record. Throws Error{kBadInput} for an invalid record,
// Error{kInvalidOption} for invalid options and Error{kFitFailed, "frames.headcenter"} when fewer
// than 3 samples carry enough normal force.
[[nodiscard]] ContactCentre SolveContactCentre(const ForceRecord& tared, const ContactSolveOptions& options);

// Commanded machine position and the centre solved there (sensor or machine frame).
struct MoveSample {
  Eigen::Vector2d commanded_mm = Eigen::Vector2d::Zero();
  Eigen::Vector2d solved_mm = Eigen::Vector2d::Zero();
  std::string label;  // e.g. the record's file name
};

struct RepeatabilityRow {
  Eigen::Vector2d commanded_mm = Eigen::Vector2d::Zero();
  int count = 0;
  Eigen::Vector2d mean_mm = Eigen::Vector2d::Zero();  // mean solved centre
  Eigen::Vector2d std_mm = Eigen::Vector2d::Zero();   // sample standard deviation (0 for one record)
  double max_deviation_mm = 0.0;                      // largest distance of a solve from the mean
};

struct AccuracyRow {
  Eigen::Vector2d commanded_mm = Eigen::Vector2d::Zero();
  double commanded_move_mm = 0.0;  // |commanded - reference commanded|
  double solved_move_mm = 0.0;     // |mean solved - reference mean solved|
  double error_mm = 0.0;           // solved_move_mm - commanded_move_mm
};

// The patent's tables: repeatability per commanded position (records repeated at one position), and
// accuracy of the moves from the reference position (the first sample's commanded position) to
// every other one. Move lengths compare whatever the frame of solved_mm, since a rigid sensor-to-
// machine transform keeps lengths. Positions are grouped when they agree within 1e-6 mm.
struct MoveTables {
  Eigen::Vector2d reference_mm = Eigen::Vector2d::Zero();
  std::vector<RepeatabilityRow> repeatability;  // in order of first appearance
  std::vector<AccuracyRow> accuracy;            // every position but the reference
  double worst_repeatability_mm = 0.0;          // largest max_deviation_mm
  double worst_accuracy_mm = 0.0;               // largest |error_mm|
};

// Throws Error{kBadInput} for an empty set.
[[nodiscard]] MoveTables TabulateMoves(std::span<const MoveSample> samples);

// A simulated pad pressing on the platform, for tests, benchmarks and demonstrations.
struct ForceSimulation {
  Eigen::Vector2d centre_mm = Eigen::Vector2d::Zero();  // true pressure centre, sensor frame
  double platform_height_mm = 20.0;
  double duration_s = 30.0;
  double sample_rate_hz = 1000.0;
  double normal_force_N = 30.0;  // mean pressing force (Fz = -normal_force_N)
  double force_ripple = 0.2;     // relative amplitude of the once-per-turn force variation
  double pad_rpm = 60.0;
  double friction_coefficient = 0.3;   // peak in-plane friction force / normal force
  double friction_couple_Nmm = 150.0;  // pad couple about the normal, per 30 N of normal force
  double approach_fraction = 0.05;     // first part of the record: force ramps up from zero
  // Gaussian noise, sigma as a fraction of the full-scale reading of each channel: the normal force
  // for the force channels, the normal force times |p| for the moment channels.
  double noise_fraction = 0.005;
  Wrench tare;  // sensor zero offset plus platform weight, added to all samples
  // Empty when valid, else one line per violation with its value, named by the flag of `arcwheel
  // headcenter simulate`: "--rate-hz = 0 violates > 0".
  [[nodiscard]] std::vector<std::string> Problems() const;
};

// The loaded record (tare included) for `simulation`; `rng` draws the noise. Both simulations
// throw Error{kInvalidOption, "frames.headcenter"} for invalid settings.
[[nodiscard]] ForceRecord SimulateForceRecord(const ForceSimulation& simulation, std::mt19937& rng);
// An unloaded record of the same length: tare plus noise.
[[nodiscard]] ForceRecord SimulateUnloadedRecord(const ForceSimulation& simulation, std::mt19937& rng);

}  // namespace arcwheel::frames
