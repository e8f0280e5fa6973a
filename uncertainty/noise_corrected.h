#pragma once
// Noise-corrected peak-to-valley figures with their standard uncertainty, by a parametric
// bootstrap (Efron & Tibshirani 1993, ch. 6 and 10: bias and standard error). Stage id
// "uncertainty.pv".
//
// A peak-to-valley of noisy values is biased upward: the range of N values of noise sigma alone is
// about d2(N) sigma. The estimator here fits each row of values (a series over phase or over the
// band) with a smooth basis (Fourier harmonics 0..max_order over a full turn, or Legendre
// polynomials 0..max_order over the band, orthonormalised over the columns), keeps each order
// whose functions lower the chi-square of all rows together by more than noise would in five
// standard deviations (dof + 5 sqrt(2 dof), dof = rows x the order's functions; in part, its
// coefficients weighted linearly from 0 at five to 1 at seven), and takes the PV of the
// fitted rows (the largest over the rows; with shrink_rows each coefficient is first shrunk towards its mean
// over the rows by the share of its spread that noise explains; with across_rows_max_degree the kept orders'
// coefficients are then fitted along the rows, for rows that are neighbours). Orders are kept one by one, not
// as a nested 0..K, so that a harmonic of noise alone between real ones does not ride on the fit: it would
// add to the PV in first order. The bootstrap then draws `replicates` new data sets, the fitted rows plus
// normal noise of each value's sigma, repeats the whole estimate (the choice of orders included) on each, and
// gives (the data sets drawn from the fit with its orders kept in part at full size)
//   bias = mean(PV*) - PV(fit at full size),   value = max(0, PV(fit) - bias),
//   u = standard deviation of the PV* whose fits keep in full just the orders the data's fit keeps
//       in full (of all PV* when the data's fit keeps none in full beyond the mean and the orders
//       the PV leaves out, or when fewer than half of the PV* do).
// The noise is taken as independent from value to value; with sigmas_from_residuals its level
// is the data's own: the sigmas are scaled by sqrt(chi-square / dof) of the fit (the Birge
// ratio) before the bootstrap.

#include <cstdint>
#include <span>
#include <string>
#include <vector>

namespace arcwheel::uncertainty {

enum class SmoothBasis {
  kFourier,   // columns equally spaced over one full turn: 1, cos c, sin c, cos 2c, ...
  kLegendre,  // columns equally spaced over an interval: P0, P1, P2, ... of u in [-1, 1]
};

struct NoiseCorrectedPvOptions {
  SmoothBasis basis = SmoothBasis::kFourier;
  // Highest order tried: harmonic (Fourier) or degree (Legendre). >= 0, and the basis of that
  // order must have fewer functions than a row has columns.
  int max_order = 24;
  // Orders below this are fitted but left out of the PV (2 for roundness: the mean and the first
  // harmonic, its least-squares circle). >= 0, <= max_order.
  int pv_from_order = 0;
  // Bootstrap data sets. >= 20.
  int replicates = 200;
  // Shrink each coefficient towards its mean over the rows by the share of its spread that the
  // noise explains: for rows that share one shape (the sections' profile error).
  bool shrink_rows = false;
  // Fit each kept order's coefficients along the rows too (the rows are neighbours along a smooth
  // coordinate, in order), with `across_rows_basis` up to this order or degree, each of its
  // functions kept when it lowers the chi-square by more than noise would in three standard
  // deviations; -1: off, each row fitted on its own.
  int across_rows_max_degree = -1;
  SmoothBasis across_rows_basis = SmoothBasis::kLegendre;
  // How many standard deviations of noise's chi-square an across-rows function must lower the
  // chi-square by to be kept. > 0.
  double across_rows_keep_sd = 3.0;
  // Scale the sigmas to the scatter of the values about the fit (see above).
  bool sigmas_from_residuals = true;
  // Seed of the bootstrap's random numbers: the same inputs give the same result.
  std::uint64_t seed = 20261203;
  // Empty when valid, else "NoiseCorrectedPvOptions::replicates = 3 violates >= 20".
  [[nodiscard]] std::vector<std::string> Problems() const;
};

struct NoiseCorrectedPv {
  double raw_pv = 0.0;     // largest over the rows of max - min of the values themselves
  double fitted_pv = 0.0;  // largest over the rows of the PV of the fitted rows
  double bias = 0.0;       // mean(PV*) - the PV of the fit with its orders kept in part at full size
  double value = 0.0;      // fitted_pv - bias: the noise-corrected estimate
  double standard_uncertainty = 0.0;  // standard deviation of PV* (see above)
  int order = 0;                      // the highest order kept that the PV counts
  double sigma_scale = 1.0;           // the Birge ratio the sigmas were scaled by
  int rows_used = 0;                  // rows with enough values to fit
  int replicates = 0;
  double dof = 0.0;  // of standard_uncertainty: replicates - 1
  // The noise-free rows the bootstrap draws about (every kept order at its full fitted size,
  // smoothed along the rows when asked), at the values' columns (filled ones too) or positions,
  // rows x columns row-major as the values; NaN where a positioned value is missing or its row is
  // left out. Other operators of the same data start their own bootstrap from them.
  std::vector<double> fitted_rows;
};

// `values` and `sigmas` hold `rows` rows of `columns` each, row-major; a NaN value is missing
// (filled by linear interpolation along its row, periodic for kFourier; a row with fewer than
// half its values present is left out). Sigmas must be finite and > 0 where values are present.
// Throws Error{kInvalidOption, "uncertainty.pv"} for bad options, Error{kBadInput} for shapes that
// do not match or no usable row.
[[nodiscard]] NoiseCorrectedPv EstimateNoiseCorrectedPv(std::span<const double> values,
                                                        std::span<const double> sigmas, int rows, int columns,
                                                        const NoiseCorrectedPvOptions& options = {});

// The same for values at positions of their own (a Legendre basis only): `positions` holds each
// value's u in [-1, 1] beside it, row-major as `values`. Each row is fitted at its values'
// positions (a section's points lie where the helix crossed the phase, a fraction of a pitch off
// the map's nodes, and the contract's arc error is their PV); a value
// whose value, sigma or position is missing is left out, not filled. The coefficients are those of
// the interval's Legendre polynomials in every row (scaled to a unit sum of squares over `columns`
// evenly spread points), so an order and its fit along the rows mean the same function in every
// row, and the PV is that of the fitted row over the whole of [-1, 1] (401 points).
[[nodiscard]] NoiseCorrectedPv EstimateNoiseCorrectedPv(std::span<const double> values,
                                                        std::span<const double> sigmas,
                                                        std::span<const double> positions, int rows,
                                                        int columns,
                                                        const NoiseCorrectedPvOptions& options = {});

// The noise-free rows alone (NoiseCorrectedPv::fitted_rows of the same call), without the
// bootstrap: for an operator other than the PV to draw its own replicates about. Throws as
// EstimateNoiseCorrectedPv.
[[nodiscard]] std::vector<double> FitNoiseFreeRows(std::span<const double> values,
                                                   std::span<const double> sigmas, int rows, int columns,
                                                   const NoiseCorrectedPvOptions& options = {});

}  // namespace arcwheel::uncertainty
