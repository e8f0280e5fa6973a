#pragma once
// The polishing tool's removal function (issue 5: "a Gaussian by peak rate and FWHM, or a measured
// map"): the removal rate (um/s) at an offset (dx, dy) from the tool centre, in the part's (x, y)
// projection. The dwell solve (dwell.h) sees it through RemovalFunction, which holds either model;
// the solve dispatches once per matrix build, so the Gaussian's rate stays an inlined call.
//
// A measured removal function is a table on a regular grid of offsets from the tool centre,
// interpolated bilinearly and zero outside the table. It is read from
//   - CSV: `#` comment lines, the header `x_mm,y_mm,rate_um_per_s`, then one node per row in any
//     order; every node of the grid must be present (write 0 where nothing is removed);
//   - HDF5 (`.h5`, `.hdf5`): dataset `/rate_um_per_s` of shape [ny][nx] (row j = y0 + j dy), with
//     the double attributes `x0_mm`, `y0_mm`, `dx_mm`, `dy_mm` on the dataset.
// Rates must be finite and >= 0 with a positive peak.
//
// The path defaults that the Gaussian derives from its width (line spacing, surface extension)
// use the footprint's equivalent sigma: sqrt((var_x + var_y) / 2) of the rate taken as a weight
// about its centroid, which is the sigma for a Gaussian table (a 2-D Gaussian has
// var_x = var_y = sigma^2), and the equivalent FWHM = 2 sqrt(2 ln 2) times that.

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <numbers>
#include <string>
#include <variant>
#include <vector>

namespace arcwheel::polishing {

// Where a removal function is non-zero: offsets from the tool centre within these bounds.
struct FootprintBox {
  double min_x_mm = 0.0, max_x_mm = 0.0, min_y_mm = 0.0, max_y_mm = 0.0;
};

struct GaussianRemovalFunction {
  double peak_rate_um_per_s = 1.0;  // removal rate at the centre, > 0
  double fwhm_mm = 10.0;            // full width at half maximum, > 0
  // Empty when valid, else one line per violation naming the job key and the value, e.g.
  // "removal_function.fwhm_mm = -2 violates > 0".
  [[nodiscard]] std::vector<std::string> Problems() const;
  [[nodiscard]] double SigmaMm() const { return fwhm_mm / (2.0 * std::sqrt(2.0 * std::numbers::ln2)); }
  [[nodiscard]] double SupportRadiusMm() const { return 3.5 * SigmaMm(); }  // the truncation radius
  // Rate at an offset from the centre; zero beyond the support radius. Inline: the removal
  // matrix evaluates it for every entry.
  [[nodiscard]] double RateUmPerS(double dx_mm, double dy_mm) const {
    const double r2 = dx_mm * dx_mm + dy_mm * dy_mm;
    const double support = SupportRadiusMm();
    if (r2 > support * support) return 0.0;
    const double sigma = SigmaMm();
    return peak_rate_um_per_s * std::exp(-r2 / (2.0 * sigma * sigma));
  }
};

// A measured removal function: rate_um_per_s[j * nx + i] at the offset (x0 + i dx, y0 + j dy).
struct TabulatedRemovalFunction {
  double x0_mm = 0.0, y0_mm = 0.0;         // offset of node (0, 0) from the tool centre
  double dx_mm = 1.0, dy_mm = 1.0;         // grid spacing, > 0
  int nx = 0, ny = 0;                      // nodes along x and y, >= 2 each
  std::vector<double> rate_um_per_s = {};  // nx * ny rates, finite, >= 0, positive peak
  std::string source = {};                 // the file it came from, for messages
  // Bilinear interpolation of the table; zero outside it.
  [[nodiscard]] double RateUmPerS(double offset_x_mm, double offset_y_mm) const {
    const double u = (offset_x_mm - x0_mm) / dx_mm, v = (offset_y_mm - y0_mm) / dy_mm;
    if (!(u >= 0.0 && v >= 0.0 && u <= nx - 1 && v <= ny - 1)) return 0.0;
    const int i = std::min(static_cast<int>(u), nx - 2), j = std::min(static_cast<int>(v), ny - 2);
    const double fu = u - i, fv = v - j;
    const double* node = rate_um_per_s.data() + static_cast<std::size_t>(j) * nx + i;
    const double bottom = node[0] + fu * (node[1] - node[0]);
    const double top = node[nx] + fu * (node[nx + 1] - node[nx]);
    return bottom + fv * (top - bottom);
  }
  // Throws Error{kBadInput, "polishing.removal"} naming the source for a malformed table.
  void Check() const;
};

class RemovalFunction {
 public:
  RemovalFunction() = default;                                                   // the default Gaussian
  RemovalFunction(GaussianRemovalFunction gaussian) : model_(gaussian) {}        // NOLINT: implicit by design
  RemovalFunction(TabulatedRemovalFunction table) : model_(std::move(table)) {}  // NOLINT

  [[nodiscard]] double RateUmPerS(double dx_mm, double dy_mm) const;
  [[nodiscard]] FootprintBox Footprint() const;
  [[nodiscard]] double PeakRateUmPerS() const;
  // The Gaussian's sigma, or a table's second-moment equivalent (see the file comment).
  [[nodiscard]] double EquivalentSigmaMm() const;
  [[nodiscard]] double EquivalentFwhmMm() const;
  [[nodiscard]] std::string Describe() const;
  // Throws Error{kInvalidOption, "polishing.dwell"} for a Gaussian out of range, or what
  // TabulatedRemovalFunction::Check throws.
  void Check() const;

  [[nodiscard]] const std::variant<GaussianRemovalFunction, TabulatedRemovalFunction>& model() const {
    return model_;
  }

 private:
  std::variant<GaussianRemovalFunction, TabulatedRemovalFunction> model_;
};

// Reads a measured removal function, HDF5 for `.h5`/`.hdf5` and CSV otherwise. Throws Error{kIo}
// if unreadable and Error{kBadInput, "polishing.removal"} naming the file and line (CSV) or dataset
// and node (HDF5) of anything malformed.
[[nodiscard]] TabulatedRemovalFunction ReadRemovalFunction(const std::filesystem::path& path);
[[nodiscard]] TabulatedRemovalFunction ReadRemovalFunctionCsv(const std::filesystem::path& path);
[[nodiscard]] TabulatedRemovalFunction ReadRemovalFunctionHdf5(const std::filesystem::path& path);

}  // namespace arcwheel::polishing
