#include "polishing/removal_function.h"

#include <fmt/core.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <fstream>
#include <iterator>
#include <limits>
#include <numbers>
#include <set>
#include <sstream>

#include "core/error.h"
#include "core/hdf5.h"
#include "polishing/grid_csv.h"

namespace arcwheel::polishing {
namespace {

constexpr const char* kRemovalFunctionStage = "polishing.removal";
constexpr double kMaxKernelNodes = 1e7;

[[noreturn]] void Bad(const std::string& what) {
  throw Error(ErrorCode::kBadInput, kRemovalFunctionStage, what);
}

double FwhmFromSigma(double sigma_mm) { return 2.0 * std::sqrt(2.0 * std::numbers::ln2) * sigma_mm; }

double SecondMomentSigmaMm(const TabulatedRemovalFunction& t) {
  double w = 0.0, sx = 0.0, sy = 0.0, sxx = 0.0, syy = 0.0;
  for (int j = 0; j < t.ny; ++j) {
    for (int i = 0; i < t.nx; ++i) {
      const double r = t.rate_um_per_s[static_cast<std::size_t>(j) * t.nx + i];
      const double x = t.x0_mm + i * t.dx_mm, y = t.y0_mm + j * t.dy_mm;
      w += r, sx += r * x, sy += r * y, sxx += r * x * x, syy += r * y * y;
    }
  }
  const double mx = sx / w, my = sy / w;
  return std::sqrt(0.5 * ((sxx / w - mx * mx) + (syy / w - my * my)));
}

}  // namespace

void TabulatedRemovalFunction::Check() const {
  const std::string where = source.empty() ? std::string("the removal table") : fmt::format("'{}'", source);
  if (nx < 2 || ny < 2)
    Bad(fmt::format("{}: the footprint grid has {} x {} nodes; it needs 2 x 2 or more", where, nx, ny));
  if (!(dx_mm > 0.0) || !(dy_mm > 0.0) || !std::isfinite(dx_mm) || !std::isfinite(dy_mm)) {
    Bad(fmt::format("{}: the grid spacing {} x {} mm must be finite and > 0", where, dx_mm, dy_mm));
  }
  if (!std::isfinite(x0_mm) || !std::isfinite(y0_mm))
    Bad(fmt::format("{}: the grid origin must be finite", where));
  if (static_cast<double>(nx) * ny > kMaxKernelNodes)
    Bad(fmt::format("{}: more than {} nodes", where, kMaxKernelNodes));
  if (rate_um_per_s.size() != static_cast<std::size_t>(nx) * ny) {
    Bad(fmt::format("{}: {} rates for a {} x {} grid", where, rate_um_per_s.size(), nx, ny));
  }
  double peak = 0.0;
  for (std::size_t k = 0; k < rate_um_per_s.size(); ++k) {
    const double r = rate_um_per_s[k];
    if (!std::isfinite(r) || r < 0.0) {
      Bad(fmt::format("{}: rate {} um/s at ({}, {}) mm must be finite and >= 0", where, r,
                      x0_mm + static_cast<double>(k % nx) * dx_mm,
                      y0_mm + static_cast<double>(k / nx) * dy_mm));
    }
    peak = std::max(peak, r);
  }
  if (!(peak > 0.0)) Bad(fmt::format("{}: the footprint removes nothing (peak rate 0 um/s)", where));
}

double RemovalFunction::RateUmPerS(double dx_mm, double dy_mm) const {
  return std::visit([&](const auto& m) { return m.RateUmPerS(dx_mm, dy_mm); }, model_);
}

FootprintBox RemovalFunction::Footprint() const {
  if (const auto* g = std::get_if<GaussianRemovalFunction>(&model_)) {
    const double r = g->SupportRadiusMm();
    return {-r, r, -r, r};
  }
  const auto& t = std::get<TabulatedRemovalFunction>(model_);
  return {t.x0_mm, t.x0_mm + (t.nx - 1) * t.dx_mm, t.y0_mm, t.y0_mm + (t.ny - 1) * t.dy_mm};
}

double RemovalFunction::PeakRateUmPerS() const {
  if (const auto* g = std::get_if<GaussianRemovalFunction>(&model_)) return g->peak_rate_um_per_s;
  const auto& rates = std::get<TabulatedRemovalFunction>(model_).rate_um_per_s;
  return rates.empty() ? 0.0 : *std::max_element(rates.begin(), rates.end());
}

double RemovalFunction::EquivalentSigmaMm() const {
  if (const auto* g = std::get_if<GaussianRemovalFunction>(&model_)) return g->SigmaMm();
  return SecondMomentSigmaMm(std::get<TabulatedRemovalFunction>(model_));
}

double RemovalFunction::EquivalentFwhmMm() const {
  if (const auto* g = std::get_if<GaussianRemovalFunction>(&model_)) return g->fwhm_mm;
  return FwhmFromSigma(EquivalentSigmaMm());
}

std::string RemovalFunction::Describe() const {
  if (const auto* g = std::get_if<GaussianRemovalFunction>(&model_)) {
    return fmt::format("Gaussian, peak {} um/s, FWHM {} mm", g->peak_rate_um_per_s, g->fwhm_mm);
  }
  const auto& t = std::get<TabulatedRemovalFunction>(model_);
  return fmt::format("measured '{}', {} x {} nodes of {} x {} mm, peak {} um/s, equivalent FWHM {:.4g} mm",
                     t.source, t.nx, t.ny, t.dx_mm, t.dy_mm, PeakRateUmPerS(), EquivalentFwhmMm());
}

void RemovalFunction::Check() const {
  if (const auto* g = std::get_if<GaussianRemovalFunction>(&model_)) {
    ThrowIfProblems(ErrorCode::kInvalidOption, "polishing.dwell", g->Problems());
    return;
  }
  std::get<TabulatedRemovalFunction>(model_).Check();
}

TabulatedRemovalFunction ReadRemovalFunction(const std::filesystem::path& path) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  return ext == ".h5" || ext == ".hdf5" ? ReadRemovalFunctionHdf5(path) : ReadRemovalFunctionCsv(path);
}

TabulatedRemovalFunction ReadRemovalFunctionCsv(const std::filesystem::path& path) {
  CsvGrid grid = ReadCsvGrid(path, "rate_um_per_s", kRemovalFunctionStage);
  for (std::size_t k = 0; k < grid.values.size(); ++k) {
    const double rate = grid.values[k];
    if (grid.lines[k] != 0 && (!std::isfinite(rate) || rate < 0.0)) {
      Bad(fmt::format("'{}' line {}: rate_um_per_s = {} must be finite and >= 0", path.string(),
                      grid.lines[k], rate));
    }
  }
  TabulatedRemovalFunction t;
  t.source = path.string();
  t.x0_mm = grid.x0_mm;
  t.y0_mm = grid.y0_mm;
  t.dx_mm = grid.dx_mm;
  t.dy_mm = grid.dy_mm;
  t.nx = grid.nx;
  t.ny = grid.ny;
  t.rate_um_per_s = std::move(grid.values);
  for (std::size_t k = 0; k < t.rate_um_per_s.size(); ++k) {
    if (std::isnan(t.rate_um_per_s[k])) {
      Bad(
          fmt::format("'{}': node ({}, {}) mm of the {} x {} footprint grid is missing (write 0 where "
                      "nothing is removed)",
                      path.string(), t.x0_mm + static_cast<double>(k % t.nx) * t.dx_mm,
                      t.y0_mm + static_cast<double>(k / t.nx) * t.dy_mm, t.nx, t.ny));
    }
  }
  t.Check();
  return t;
}

TabulatedRemovalFunction ReadRemovalFunctionHdf5(const std::filesystem::path& path) {
  hdf5::ReadFirstInChildProcess(path, [&] { (void)ReadRemovalFunctionHdf5(path); });
  const hdf5::File file = hdf5::File::OpenReadOnly(path);
  const std::string dataset = "rate_um_per_s";
  auto fail = [&](const std::string& what) {
    Bad(fmt::format("'{}' dataset '/{}': {}", path.string(), dataset, what));
  };
  if (!file.HasObject(dataset)) fail("is missing");
  const std::vector<hsize_t> shape = file.Shape(dataset);
  if (shape.size() != 2) fail(fmt::format("has rank {}; it must be [ny][nx]", shape.size()));
  if (static_cast<double>(shape[0]) * static_cast<double>(shape[1]) > kMaxKernelNodes)
    fail(fmt::format("has more than {} nodes", kMaxKernelNodes));
  TabulatedRemovalFunction t;
  t.source = path.string();
  t.ny = static_cast<int>(shape[0]);
  t.nx = static_cast<int>(shape[1]);
  auto attribute = [&](const std::string& name) {
    const std::optional<double> v = file.ReadAttributeDouble(dataset, name);
    if (!v) fail(fmt::format("attribute '{}' is missing", name));
    if (!std::isfinite(*v)) fail(fmt::format("attribute '{}' = {} must be finite", name, *v));
    return *v;
  };
  t.x0_mm = attribute("x0_mm");
  t.y0_mm = attribute("y0_mm");
  t.dx_mm = attribute("dx_mm");
  t.dy_mm = attribute("dy_mm");
  if (!(t.dx_mm > 0.0) || !(t.dy_mm > 0.0))
    fail(fmt::format("dx_mm = {} and dy_mm = {} must be > 0", t.dx_mm, t.dy_mm));
  if (t.nx < 2 || t.ny < 2)
    fail(fmt::format("is {} x {}; the footprint needs 2 x 2 nodes or more", t.ny, t.nx));
  t.rate_um_per_s = file.ReadDoubles(dataset);
  for (std::size_t k = 0; k < t.rate_um_per_s.size(); ++k) {
    const double r = t.rate_um_per_s[k];
    if (!std::isfinite(r) || r < 0.0) {
      fail(fmt::format("[{}][{}] = {} um/s must be finite and >= 0", k / static_cast<std::size_t>(t.nx),
                       k % static_cast<std::size_t>(t.nx), r));
    }
  }
  t.Check();
  return t;
}

std::vector<std::string> GaussianRemovalFunction::Problems() const {
  std::vector<std::string> problems;
  if (!(peak_rate_um_per_s > 0.0 && std::isfinite(peak_rate_um_per_s))) {
    problems.push_back(
        fmt::format("removal_function.peak_rate_um_per_s = {} violates > 0", peak_rate_um_per_s));
  }
  if (!(fwhm_mm > 0.0 && std::isfinite(fwhm_mm)))
    problems.push_back(fmt::format("removal_function.fwhm_mm = {} violates > 0", fwhm_mm));
  return problems;
}

}  // namespace arcwheel::polishing
