// Error maps from Zygo Mx `.datx` files (HDF5).
#include <fmt/core.h>

#include <cmath>
#include <cstddef>
#include <filesystem>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "core/error.h"
#include "core/hdf5.h"
#include "polishing/error_map_io.h"
#include "polishing/error_map_io_impl.h"

namespace arcwheel::polishing {
namespace {

using namespace internal;

// Zygo Mx .datx. Layout as read by ContactEngineering SurfaceTopography (IO/DATX.py) and prysm
// (io.read_zygo_datx): a surface dataset with attributes `No Data`, `Unit`, `X Converter`,
// `Y Converter`, `Z Converter`; a converter is a compound {Category, BaseUnit, Parameters}.
// Where the surface dataset is: see DatxSurfacePath.
constexpr const char* kDatxMetaData = "/MetaData";
constexpr const char* kDatxMeasurementSurface = "/Measurement/Surface";
constexpr const char* kDatxDataSurface = "/Data/Surface";

// The destination of the /MetaData row (source, link), or nothing. Two rows that disagree are
// refused: which surface is meant would be a guess.
std::optional<std::string> MetaDataLink(const std::vector<std::vector<std::string>>& rows,
                                        const std::string& source, const std::string& link,
                                        const std::string& name) {
  std::optional<std::string> destination;
  for (const std::vector<std::string>& row : rows) {
    if (row[0] != source || row[1] != link) continue;
    if (destination && *destination != row[2]) {
      Fail(name, fmt::format("{} links '{}' -> '{}' to both '{}' and '{}'", kDatxMetaData, source, link,
                             *destination, row[2]));
    }
    destination = row[2];
  }
  return destination;
}

// The surface's path as the /MetaData table names it (Root -> Measurement -> Surface -> Path, as
// MetroPro writes it and SurfaceTopography reads it), or nothing if the table does not name one.
std::optional<std::string> DatxSurfaceFromMetaData(const hdf5::File& file) {
  const std::string name = file.path().string();
  const std::vector<std::vector<std::string>> rows =
      file.ReadStringTable(kDatxMetaData, {"Source", "Link", "Destination"});
  std::string node = "Root";
  for (const char* link : {"Measurement", "Surface", "Path"}) {
    const std::optional<std::string> next = MetaDataLink(rows, node, link, name);
    if (!next) return std::nullopt;
    node = *next;
  }
  return node;
}

// Where the surface dataset of a .datx is: the path /MetaData names (MetroPro's files put the
// surface at /Data/Surface/{GUID}); else /Measurement/Surface; else the only dataset under
// /Data/Surface (as prysm takes it). A path that /MetaData names but the file lacks is refused.
std::string DatxSurfacePath(const hdf5::File& file) {
  const std::string name = file.path().string();
  if (file.HasObject(kDatxMetaData)) {
    if (const std::optional<std::string> path = DatxSurfaceFromMetaData(file)) {
      if (path->empty() || path->front() != '/' || !file.HasObject(*path)) {
        Fail(name, fmt::format("{} names the surface dataset '{}', which the file does not hold",
                               kDatxMetaData, *path));
      }
      return *path;
    }
  }
  if (file.HasObject(kDatxMeasurementSurface)) return kDatxMeasurementSurface;
  const std::vector<std::string> datasets = file.DatasetNames(kDatxDataSurface);
  if (datasets.size() == 1) return std::string(kDatxDataSurface) + "/" + datasets.front();
  if (datasets.size() > 1) {
    Fail(name, fmt::format("'{}' holds {} datasets and no {} table says which is the surface",
                           kDatxDataSurface, datasets.size(), kDatxMetaData));
  }
  Fail(name,
       fmt::format("no surface dataset: neither a {} table naming one, nor '{}', nor a dataset under '{}' "
                   "(not a Zygo Mx .datx surface measurement?)",
                   kDatxMetaData, kDatxMeasurementSurface, kDatxDataSurface));
}

// Micrometres per base unit of a height, or NaN for a unit that is not a length.
double MicrometresPer(const std::string& unit) {
  if (unit == "Meters") return 1e6;
  if (unit == "MilliMeters") return 1e3;
  if (unit == "MicroMeters") return 1.0;
  if (unit == "NanoMeters") return 1e-3;
  if (unit == "Angstroms") return 1e-4;
  return kNaN;
}

double DatxAttribute(const hdf5::File& file, const std::string& surface, const std::string& attribute) {
  const std::optional<double> v = file.ReadAttributeDouble(surface, attribute);
  if (!v || !std::isfinite(*v) || *v == 0.0) {
    Fail(file.path().string(), fmt::format("{} attribute '{}' is {} (needed for heights in Fringes)", surface,
                                           attribute, v ? fmt::format("{}", *v) : std::string("missing")));
  }
  return *v;
}

// Micrometres per stored height value, from the Z converter.
double DatxHeightScaleUm(const hdf5::File& file, const std::string& surface) {
  const std::string name = file.path().string();
  const auto z = file.ReadAttributeCompound(surface, "Z Converter");
  if (!z) Fail(name, fmt::format("{} has no attribute 'Z Converter' (the height unit)", surface));
  const std::string category = z->strings.count("Category") ? z->strings.at("Category") : "";
  const std::string unit = z->strings.count("BaseUnit") ? z->strings.at("BaseUnit") : "";
  if (category != "HeightCat") {
    Fail(name,
         fmt::format("{} attribute 'Z Converter' Category = '{}' is not 'HeightCat'", surface, category));
  }
  if (unit == "Fringes") {
    // As prysm: fringes * wavelength * interferometric scale factor * obliquity factor = height.
    return 1e6 * DatxAttribute(file, surface, "Wavelength") *
           DatxAttribute(file, surface, "Interferometric Scale Factor") *
           DatxAttribute(file, surface, "Obliquity Factor");
  }
  const double um = MicrometresPer(unit);
  if (std::isnan(um)) {
    Fail(name, fmt::format("{} attribute 'Z Converter' BaseUnit = '{}' is not a length (Meters, MilliMeters, "
                           "MicroMeters, NanoMeters, Angstroms) or Fringes",
                           surface, unit));
  }
  return um;
}

// mm per pixel from an X or Y converter (Parameters[1] in m), NaN if absent or not lateral.
double DatxPixelMm(const hdf5::File& file, const std::string& surface, const std::string& converter) {
  const auto c = file.ReadAttributeCompound(surface, converter);
  if (!c || !c->strings.count("Category") || c->strings.at("Category") != "LateralCat" ||
      !c->numbers.count("Parameters")) {
    return kNaN;
  }
  const std::vector<double>& p = c->numbers.at("Parameters");
  if (p.size() < 2 || !std::isfinite(p[1]) || !(p[1] > 0.0)) return kNaN;
  return p[1] * 1e3;
}

}  // namespace

PixelMap ReadZygoDatx(const hdf5::File& file) {
  const std::string name = file.path().string();
  const std::string surface = DatxSurfacePath(file);
  const std::vector<hsize_t> shape = file.Shape(surface);
  if (shape.size() != 2 || shape[0] == 0 || shape[1] == 0 || shape[0] > 1u << 20 || shape[1] > 1u << 20) {
    std::string dims;
    for (const hsize_t d : shape) dims += (dims.empty() ? "" : " x ") + std::to_string(d);
    Fail(name, fmt::format("dataset '{}' has shape [{}], needs [rows][columns]", surface, dims));
  }
  CheckMapNodes(name, fmt::format("dataset '{}'", surface), static_cast<double>(shape[0]),
                static_cast<double>(shape[1]));
  const H5T_class_t element = file.ElementClass(surface);
  if (element != H5T_FLOAT && element != H5T_INTEGER)
    Fail(name, fmt::format("dataset '{}' is not numeric", surface));
  const double um = DatxHeightScaleUm(file, surface);
  const std::optional<double> no_data = file.ReadAttributeDouble(surface, "No Data");
  PixelMap map;
  map.height = static_cast<int>(shape[0]);
  map.width = static_cast<int>(shape[1]);
  map.pixel_x_mm = DatxPixelMm(file, surface, "X Converter");
  map.pixel_y_mm = DatxPixelMm(file, surface, "Y Converter");
  map.height_um = file.ReadDoubles(surface);
  // No data: the file's `No Data` value (MetroPro writes the largest double; a file whose
  // marker is infinity marks its gaps with it) or NaN. Any other value that is not finite, or
  // whose height overflows, is damage.
  for (std::size_t k = 0; k < map.height_um.size(); ++k) {
    double& v = map.height_um[k];
    if (std::isnan(v) || (no_data && v == *no_data)) {
      v = kNaN;
      continue;
    }
    const double height_um = v * um;
    if (!std::isfinite(height_um)) {
      Fail(name,
           fmt::format("dataset '{}' value [{}][{}] = {} is not a finite height (its No Data value is {})",
                       surface, k / shape[1], k % shape[1], v,
                       no_data ? fmt::format("{}", *no_data) : std::string("not given")));
    }
    v = height_um;
  }
  return map;
}

PixelMap ReadZygoDatx(const std::filesystem::path& path) {
  hdf5::ReadFirstInChildProcess(path, [&] { (void)ReadZygoDatx(hdf5::File::OpenReadOnly(path)); });
  return ReadZygoDatx(hdf5::File::OpenReadOnly(path));
}

}  // namespace arcwheel::polishing
