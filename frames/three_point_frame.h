#pragma once
// The three-point workpiece frame (method.md E) and the PMAC/UMAC axis definitions that realise it.
//
// Probe P1 (the workpiece origin), P2 (a point on the workpiece +X axis) and P3 (a point in the
// workpiece XY plane on the +Y side), all in machine coordinates:
//   i = (P2 - P1) / |P2 - P1|,  j = the part of (P3 - P1) orthogonal to i, normalised,  k = i x j.
//   workpiece -> machine:  P' = P1 + [i j k] P;     machine -> workpiece:  P = [i j k]^T (P' - P1).

#include <Eigen/Core>
#include <array>
#include <string>
#include <vector>

#include "frames/transform.h"

namespace arcwheel::frames {

struct ThreePointFrameOptions {
  // P2 and P3 must each lie at least this far from P1, in mm. > 0.
  double min_separation_mm = 1e-3;
  // The angle between P2 - P1 and P3 - P1 (and its supplement) must be at least this, in degrees;
  // below it the points are called collinear. In (0, 90).
  double min_angle_deg = 0.1;
  // Empty when valid, else one line per violation with its value, named by the flag of `arcwheel
  // frame`: "--min-angle-deg = 90 violates (0, 90)".
  [[nodiscard]] std::vector<std::string> Problems() const;
};

struct WorkpieceFrame {
  Eigen::Vector3d origin_mm = Eigen::Vector3d::Zero();   // P1, in machine coordinates
  Eigen::Matrix3d axes = Eigen::Matrix3d::Identity();    // columns i, j, k in machine coordinates
  double angle_p2_p3_deg = 90.0;                         // angle at P1 between P2 and P3
  [[nodiscard]] Transform MachineFromWorkpiece() const;  // rigid3d
  [[nodiscard]] Transform WorkpieceFromMachine() const;  // rigid3d
};

// Throws Error{kBadInput, "frames.three_point"} for coincident or collinear points or non-finite
// coordinates, naming the points and the measured distance or angle.
[[nodiscard]] WorkpieceFrame ThreePointFrame(const Eigen::Vector3d& p1_mm, const Eigen::Vector3d& p2_mm,
                                             const Eigen::Vector3d& p3_mm,
                                             const ThreePointFrameOptions& options = {});

struct PmacAxisOptions {
  int coordinate_system = 1;              // &n, >= 1
  std::array<int, 3> motors = {1, 2, 3};  // motors driving machine X, Y, Z; >= 1, distinct
  // Counts per mm of each machine axis motor (sign gives its direction), non-zero.
  std::array<double, 3> counts_per_mm = {1.0, 1.0, 1.0};
  // Digits after the decimal point of the coefficients (PMAC takes floating-point scale factors).
  int decimals = 6;
  // Empty when valid, else one line per violation with its value, named by the flag of `arcwheel
  // frame pmac`: "--motors = 1,1,3 violates distinct and >= 1".
  [[nodiscard]] std::vector<std::string> Problems() const;
};

// The coordinate-system definition `&c` and one `#n->AnX+BnY+CnZ+Dn` line per motor, such that
// commanding workpiece coordinates (X, Y, Z) drives motor n to counts_n * (P1 + [i j k] (X,Y,Z))_n:
//   A..C = counts_per_mm[n] * row n of [i j k],   D = counts_per_mm[n] * P1_n   (counts).
// Machine coordinates are taken to be motor position / counts_per_mm (motor zero = machine zero).
// Throws Error{kInvalidOption} for invalid options.
[[nodiscard]] std::vector<std::string> PmacAxisDefinitions(const Transform& machine_from_workpiece,
                                                           const PmacAxisOptions& options);

}  // namespace arcwheel::frames
