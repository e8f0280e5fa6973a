// formats.md 2.1.

#include <cmath>
#include <limits>
#include <optional>
#include <span>
#include <string>
#include <type_traits>
#include <utility>
#include <variant>
#include <vector>

#include "acquisition/read_in_child.h"
#include "acquisition/scan_format.h"
#include "acquisition/scan_metadata_keys.h"
#include "acquisition/scan_reader.h"
#include "core/check.h"
#include "core/error.h"
#include "core/hdf5.h"

namespace arcwheel::acquisition {
namespace {

constexpr const char* kHdf5ReaderStage = "acquisition.hdf5";

void CheckOneDimensional(const hdf5::File& file, const std::string& name) {
  const std::vector<hsize_t> shape = file.Shape(name);
  if (shape.size() != 1) {
    throw Error(ErrorCode::kBadInput, kHdf5ReaderStage,
                "'" + file.path().string() + "' dataset " + name + " must be one-dimensional, has rank " +
                    std::to_string(shape.size()));
  }
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
      throw Error(ErrorCode::kBadInput, kHdf5ReaderStage,
                  "'" + file.path().string() + "' /scan: " + error.what());
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

// How /scan/z is stored: float32 or float64 millimetres, or integer sensor counts with the CF
// convention's `scale_factor` (mm per count) and optional `add_offset` (mm); invalid_value is then
// compared with the counts.
struct ZLayout {
  bool is_float = true;
  bool is_float32 = false;
  double scale = 1.0;
  double offset = 0.0;
};

ZLayout ReadZLayout(const hdf5::File& file) {
  const std::string name = "/scan/z";
  CheckOneDimensional(file, name);
  ZLayout layout;
  if (file.ElementClass(name) == H5T_FLOAT) {
    layout.is_float32 = file.ElementSize(name) == 4;
    return layout;
  }
  layout.is_float = false;
  const std::optional<double> scale = file.ReadAttributeDouble(name, "scale_factor");
  if (!scale) {
    throw Error(ErrorCode::kBadInput, kHdf5ReaderStage,
                "'" + file.path().string() +
                    "' dataset /scan/z stores integers (sensor counts?), not millimetres: "
                    "give their scale as attribute scale_factor (mm per count, and add_offset in mm if any) "
                    "on /scan/z, "
                    "or store z as float in mm");
  }
  layout.scale = *scale;
  layout.offset = file.ReadAttributeDouble(name, "add_offset").value_or(0.0);
  if (!std::isfinite(layout.scale) || layout.scale == 0.0 || !std::isfinite(layout.offset)) {
    throw Error(
        ErrorCode::kBadInput, kHdf5ReaderStage,
        "'" + file.path().string() + "' /scan/z: scale_factor must be finite and not 0, add_offset finite");
  }
  return layout;
}

SentinelComparison ComparisonOf(const ZLayout& layout) {
  if (!layout.is_float) return SentinelComparison::kDone;  // compared with the counts on reading
  return layout.is_float32 ? SentinelComparison::kAsFloat : SentinelComparison::kAsDouble;
}

// The optional columns, as formats.md 2.1 names them.
constexpr std::pair<const char*, std::vector<double> Scan::*> kColumns[] = {
    {"/scan/t", &Scan::t_s}, {"/scan/angle", &Scan::angle_deg}, {"/scan/y", &Scan::y_mm}};

// Where the columns' values go: the scan's own vectors, or arrays shared with a parent process.
// float32 readings kept as they are stored are not read when `leave_in_file(name)` says that the
// parent maps them from the file (it returns false where they cannot be: then they are read).
template <typename Allocator, typename LeaveInFile>
void ReadColumns(const hdf5::File& file, const ScanMetadata& metadata, const ReadOptions& options,
                 Allocator&& allocate, LeaveInFile&& leave_in_file) {
  const ZLayout layout = ReadZLayout(file);
  const std::string z = "/scan/z";
  if (layout.is_float32 && options.keep_float32) {
    if (!leave_in_file(z)) file.ReadInto(z, allocate(z, file.NumericCount(z, sizeof(float)), float{}));
  } else {
    const std::span<double> values = allocate(z, file.NumericCount(z, sizeof(double)), double{});
    file.ReadInto(z, values);
    if (!layout.is_float) {
      for (double& value : values) {
        value = metadata.invalid_value && value == *metadata.invalid_value
                    ? std::numeric_limits<double>::quiet_NaN()
                    : value * layout.scale + layout.offset;
      }
    }
  }
  for (const auto& [name, member] : kColumns) {
    if (!file.HasObject(name)) continue;
    CheckOneDimensional(file, name);
    file.ReadInto(name, allocate(name, file.NumericCount(name, sizeof(double)), double{}));
  }
}

// The group, its attributes and the presence of /scan/z: everything but the data.
Scan ReadHeader(const hdf5::File& file) {
  const std::filesystem::path& path = file.path();
  if (!file.HasObject("/scan")) {
    throw Error(ErrorCode::kBadInput, kHdf5ReaderStage, "'" + path.string() + "' has no group /scan");
  }
  Scan scan;
  scan.path = path.string();
  ReadAttributes(file, scan.metadata);
  if (!file.HasObject("/scan/z")) {
    throw Error(ErrorCode::kBadInput, kHdf5ReaderStage, "'" + path.string() + "' has no dataset /scan/z");
  }
  return scan;
}

// The vector of `scan` that holds the double values of `name`.
std::vector<double>& DoubleColumnOf(Scan& scan, const std::string& name) {
  if (name == "/scan/z") return scan.z_mm;
  for (const auto& [column, member] : kColumns) {
    if (name == column) return scan.*member;
  }
  throw Error(ErrorCode::kInternal, kHdf5ReaderStage, "no scan column for " + name);
}

// Invalid markers, then formats.md 2.3.
Scan Finish(Scan scan, const hdf5::File& file, const ReadOptions& options) {
  scan.read.format = "hdf5";
  ApplyInvalidMarkers(scan, ComparisonOf(ReadZLayout(file)));
  FinishScan(scan, options);
  return scan;
}

}  // namespace

namespace internal {

void ReadHelixInChild(const hdf5::File& file, const ReadOptions& options, hdf5::SharedArrays& shared) {
  const Scan header = ReadHeader(file);
  ReadColumns(
      file, header.metadata, options,
      [&](const std::string& name, std::size_t count, auto type) {
        return shared.Allocate<decltype(type)>(name, count);
      },
      [&](const std::string& name) {
        const std::optional<hdf5::FileExtent> extent = file.ContiguousFloat32Extent(name);
        if (extent) shared.LeaveInFile<float>(name, *extent);
        return extent.has_value();
      });
}

Scan HelixFromChild(const hdf5::File& file, hdf5::SharedArrays& arrays, bool handed,
                    const ReadOptions& options) {
  if (!handed) return ReadHdf5Scan(file, options);
  Scan scan = ReadHeader(file);
  // The float32 readings (the largest column, and the one a large scan has) stay in the pages the
  // child wrote, or in the file's own pages where the file stores them as they are kept; the
  // double columns are copied out into vectors.
  if (auto z = arrays.Map<float>("/scan/z")) scan.z_float_mm = FloatColumn(z->values, std::move(z->mapping));
  const auto take = [&](const std::string& name) {
    if (std::optional<std::vector<double>> values = arrays.Take<double>(name))
      DoubleColumnOf(scan, name) = std::move(*values);
  };
  take("/scan/z");
  for (const auto& [name, member] : kColumns) take(name);
  return Finish(std::move(scan), file, options);
}

}  // namespace internal

Scan ReadHdf5Scan(const std::filesystem::path& path, const ReadOptions& options) {
  // The data are read once, in the child process that guards against libhdf5 crashing on a
  // damaged file; here only the header is read again (what the child has already read safely).
  hdf5::SharedArrays arrays;
  const bool handed = hdf5::ReadInChildProcess(
      path, arrays,
      [&](hdf5::SharedArrays& shared) {
        internal::ReadHelixInChild(hdf5::File::OpenReadOnly(path), options, shared);
      },
      0.0);
  return internal::HelixFromChild(hdf5::File::OpenReadOnly(path), arrays, handed, options);
}

Scan ReadHdf5Scan(const hdf5::File& file, const ReadOptions& options) {
  Scan scan = ReadHeader(file);
  ReadColumns(
      file, scan.metadata, options,
      [&](const std::string& name, std::size_t count, auto type) {
        if constexpr (std::is_same_v<decltype(type), float>) {
          scan.z_float_mm = std::vector<float>(count);
          return std::span<float>(scan.z_float_mm);
        } else {
          std::vector<double>& column = DoubleColumnOf(scan, name);
          column.resize(count);
          return std::span<double>(column);
        }
      },
      [](const std::string&) { return false; });
  return Finish(std::move(scan), file, options);
}

std::variant<Scan, ProfileScan> ReadAnyScan(const std::filesystem::path& path, const ReadOptions& options) {
  const ScanFormat format =
      ScanFormatOfContent(path, options.format, !options.columns.empty(), "acquisition");
  if (format != ScanFormat::kHdf5 || !options.format.empty()) {
    if (!IsProfileFormat(format)) return ReadScan(path, options);
    // Beside a text export's parsing; not before the HDF5 layout's reader, which forks (no thread
    // may be alive then): the caller starts its work after that read.
    if (format != ScanFormat::kProfileHdf5 && options.while_reading) options.while_reading();
    return ReadProfileScan(path, format, options.settings);
  }
  // One child reads the file as the kind its groups tell (a /profile group: a line-profile scan).
  hdf5::SharedArrays arrays;
  const bool handed = hdf5::ReadInChildProcess(
      path, arrays,
      [&](hdf5::SharedArrays& shared) {
        const hdf5::File file = hdf5::File::OpenReadOnly(path);
        if (file.HasObject("/profile")) {
          internal::ReadProfileInChild(file, shared);
        } else {
          internal::ReadHelixInChild(file, options, shared);
        }
      },
      0.0);
  const hdf5::File file = hdf5::File::OpenReadOnly(path);
  if (file.HasObject("/profile")) return internal::ProfileFromChild(file, arrays, handed, options.settings);
  return internal::HelixFromChild(file, arrays, handed, options);
}

Scan ReadScan(const std::filesystem::path& path, const ReadOptions& options) {
  const ScanFormat format =
      ScanFormatOfContent(path, options.format, !options.columns.empty(), "acquisition");
  if (format == ScanFormat::kHdf5) return ReadHdf5Scan(path, options);
  if (options.while_reading) options.while_reading();
  switch (format) {
    case ScanFormat::kCsv:
      return ReadCsvScan(path, options);
    case ScanFormat::kSensorTool:
    case ScanFormat::kKeyenceLk:
    case ScanFormat::kColumns:
      return ReadSensorScan(path, format, options);
    case ScanFormat::kHdf5:
      break;
    case ScanFormat::kProfileHdf5:
    case ScanFormat::kGocator:
    case ScanFormat::kKeyenceLj:
      throw Error(ErrorCode::kBadInput, "acquisition",
                  "'" + path.string() + "' is a line-profile scan (" + std::string(InfoOf(format).name) +
                      "): read it with ReadProfileScan (acquisition/profile_scan.h)");
  }
  ARCWHEEL_CHECK(false) << "scan format without a reader";
  return {};
}

}  // namespace arcwheel::acquisition
