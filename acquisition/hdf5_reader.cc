// formats.md 2.1.

#include <cmath>
#include <limits>
#include <string>

#include "acquisition/scan_metadata_keys.h"
#include "acquisition/scan_reader.h"
#include "core/error.h"
#include "core/hdf5.h"

namespace arcwheel::acquisition {
namespace {

constexpr const char* kStage = "acquisition.hdf5";

std::vector<double> ReadColumn(const hdf5::File& file, const std::string& name) {
  const std::vector<hsize_t> shape = file.Shape(name);
  if (shape.size() != 1) {
    throw Error(ErrorCode::kBadInput, kStage,
                "'" + file.path().string() + "' dataset " + name + " must be one-dimensional, has rank " +
                    std::to_string(shape.size()));
  }
  return file.ReadDoubles(name);
}

// Every attribute on /scan, matched to formats.md's keys case-insensitively; the unused ones noted.
void ReadAttributes(const hdf5::File& file, ScanMetadata& metadata) {
  MetadataSetter setter(metadata);
  // The setter's messages name the key; the file's own name the file and the attribute.
  const auto in_this_file = [&](const auto& step) {
    try {
      return step();
    } catch (const Error& error) {
      if (error.code() != ErrorCode::kBadInput) throw;
      throw Error(ErrorCode::kBadInput, kStage, "'" + file.path().string() + "' /scan: " + error.what());
    }
  };
  for (const std::string& attribute : file.AttributeNames("/scan")) {
    const std::string key = in_this_file([&] { return setter.Claim(attribute); });
    if (key.empty()) continue;
    if (MetadataSetter::IsNumeric(key)) {
      const double value = *file.ReadAttributeDouble("/scan", attribute);
      in_this_file([&] { setter.SetNumber(key, value); });
    } else {
      const std::string value = *file.ReadAttributeString("/scan", attribute);
      in_this_file([&] { setter.SetText(key, value); });
    }
  }
}

// z in mm. Integer z are sensor counts: they need the CF convention's `scale_factor` (mm per count)
// and optional `add_offset` (mm) on /scan/z; invalid_value is then compared with the counts.
std::vector<double> ReadZ(const hdf5::File& file, ScanMetadata& metadata, SentinelComparison& comparison) {
  const std::string name = "/scan/z";
  std::vector<double> z = ReadColumn(file, name);
  const H5T_class_t type_class = file.ElementClass(name);
  if (type_class == H5T_FLOAT) {
    comparison = file.ElementSize(name) == 4 ? SentinelComparison::kAsFloat : SentinelComparison::kAsDouble;
    return z;
  }
  const std::optional<double> scale = file.ReadAttributeDouble(name, "scale_factor");
  if (!scale) {
    throw Error(ErrorCode::kBadInput, kStage,
                "'" + file.path().string() +
                    "' dataset /scan/z stores integers (sensor counts?), not millimetres: "
                    "give their scale as attribute scale_factor (mm per count, and add_offset in mm if any) "
                    "on /scan/z, "
                    "or store z as float in mm");
  }
  const double offset = file.ReadAttributeDouble(name, "add_offset").value_or(0.0);
  if (!std::isfinite(*scale) || *scale == 0.0 || !std::isfinite(offset)) {
    throw Error(
        ErrorCode::kBadInput, kStage,
        "'" + file.path().string() + "' /scan/z: scale_factor must be finite and not 0, add_offset finite");
  }
  for (double& value : z) {
    value = metadata.invalid_value && value == *metadata.invalid_value
                ? std::numeric_limits<double>::quiet_NaN()
                : value * *scale + offset;
  }
  comparison = SentinelComparison::kDone;
  return z;
}

}  // namespace

Scan ReadHdf5Scan(const std::filesystem::path& path) {
  hdf5::ReadFirstInChildProcess(path, [&] { (void)ReadHdf5Scan(hdf5::File::OpenReadOnly(path)); });
  return ReadHdf5Scan(hdf5::File::OpenReadOnly(path));
}

Scan ReadHdf5Scan(const hdf5::File& file) {
  const std::filesystem::path& path = file.path();
  if (!file.HasObject("/scan")) {
    throw Error(ErrorCode::kBadInput, kStage, "'" + path.string() + "' has no group /scan");
  }
  Scan scan;
  scan.path = path.string();
  ReadAttributes(file, scan.metadata);
  if (!file.HasObject("/scan/z")) {
    throw Error(ErrorCode::kBadInput, kStage, "'" + path.string() + "' has no dataset /scan/z");
  }
  SentinelComparison comparison = SentinelComparison::kAsDouble;
  scan.z_mm = ReadZ(file, scan.metadata, comparison);
  if (file.HasObject("/scan/t")) scan.t_s = ReadColumn(file, "/scan/t");
  if (file.HasObject("/scan/angle")) scan.angle_deg = ReadColumn(file, "/scan/angle");
  if (file.HasObject("/scan/y")) scan.y_mm = ReadColumn(file, "/scan/y");
  ApplyInvalidMarkers(scan, comparison);
  ValidateScan(scan);
  return scan;
}

Scan ReadScan(const std::filesystem::path& path) {
  std::string extension = path.extension().string();
  for (char& c : extension) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  if (extension == ".h5" || extension == ".hdf5") return ReadHdf5Scan(path);
  if (extension == ".csv" || extension == ".txt") return ReadCsvScan(path);
  throw Error(ErrorCode::kBadInput, "acquisition",
              "'" + path.string() + "': unknown scan file type '" + extension +
                  "' (expected .h5, .hdf5, .csv or .txt)");
}

}  // namespace arcwheel::acquisition
