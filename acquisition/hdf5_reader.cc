// formats.md 2.1.

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

void ReadAttributes(const hdf5::File& file, ScanMetadata& metadata) {
  for (const char* key : kNumericMetadataKeys) {
    if (const auto value = file.ReadAttributeDouble("/scan", key)) SetNumericMetadata(metadata, key, *value);
  }
  for (const char* key : kTextMetadataKeys) {
    if (const auto value = file.ReadAttributeString("/scan", key)) SetMetadata(metadata, key, *value);
  }
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
  scan.z_mm = ReadColumn(file, "/scan/z");
  if (file.HasObject("/scan/t")) scan.t_s = ReadColumn(file, "/scan/t");
  if (file.HasObject("/scan/angle")) scan.angle_deg = ReadColumn(file, "/scan/angle");
  if (file.HasObject("/scan/y")) scan.y_mm = ReadColumn(file, "/scan/y");
  const bool stored_as_float = file.ElementClass("/scan/z") == H5T_FLOAT && file.ElementSize("/scan/z") == 4;
  ApplyInvalidMarkers(scan, stored_as_float);
  ValidateScan(scan);
  return scan;
}

Scan ReadScan(const std::filesystem::path& path) {
  std::string extension = path.extension().string();
  for (char& c : extension) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  if (extension == ".h5" || extension == ".hdf5") return ReadHdf5Scan(path);
  if (extension == ".csv" || extension == ".txt") return ReadCsvScan(path);
  throw Error(ErrorCode::kBadInput, "acquisition",
              "'" + path.string() + "': unknown scan file type '" + extension + "' (expected .h5, .hdf5, .csv or .txt)");
}

}  // namespace arcwheel::acquisition
