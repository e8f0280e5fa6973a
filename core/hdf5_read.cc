// arcwheel::hdf5's reads of numeric datasets: their sizes checked before anything is allocated,
// and a failed read explained where a filter plugin is missing.
#include <fcntl.h>
#include <hdf5.h>
#include <unistd.h>

#include <algorithm>
#include <bit>
#include <cstddef>
#include <cstring>
#include <span>
#include <string>
#include <vector>

#include "core/error.h"
#include "core/hdf5.h"
#include "core/hdf5_impl.h"

namespace arcwheel::hdf5 {

namespace internal {

void CheckNumberSize(hid_t type, const std::string& what) {
  const size_t size = H5Tget_size(type);
  if (size == 0 || size > 16) {
    throw Error(ErrorCode::kBadInput, kStage,
                what + " has numbers of " + std::to_string(size) + " bytes (damaged?)");
  }
}

}  // namespace internal

namespace {

using namespace internal;

// A filter libhdf5 cannot apply (a plugin that is not installed) fails H5Dread with no word of
// why: after a failed read, name it, with the Debian package that brings it where there is one.
// (libhdf5 1.10 loads a plugin only when a read needs it, so H5Zfilter_avail says "no" for an
// installed one until then: it is asked only after the read.)
void CheckFiltersAvailable(const Handle& data, const std::string& where) {
  const Handle creation(H5Dget_create_plist(data.id()), H5Pclose);
  const int filters = creation.valid() ? H5Pget_nfilters(creation.id()) : 0;
  for (int k = 0; k < filters; ++k) {
    unsigned flags = 0, config = 0;
    size_t values = 0;
    char name[256] = {};
    const H5Z_filter_t id = H5Pget_filter2(creation.id(), static_cast<unsigned>(k), &flags, &values, nullptr,
                                           sizeof name, name, &config);
    if (id < 0 || H5Zfilter_avail(id) > 0) continue;
    std::string package;
    if (id == 32000) package = " (Debian package hdf5-plugin-lzf)";
    if (id == 307 || id == 32004 || id == 32008) package = " (Debian package hdf5-filter-plugin)";
    if (id == 32001) package = " (Debian package hdf5-filter-plugin-blosc-serial)";
    throw Error(ErrorCode::kBadInput, kStage,
                where + " is compressed with HDF5 filter " + std::to_string(id) +
                    (name[0] ? " '" + std::string(name) + "'" : "") +
                    ", which this HDF5 installation cannot decode: install its plugin" + package +
                    " or rewrite the file with gzip");
  }
}

// The number of values in a numeric dataset, refused when the header declares more than the file
// could hold even compressed 64 to 1 (`value_bytes` each in memory), before anything is allocated.
std::size_t NumericCount(hid_t file_id, const Handle& data, std::size_t value_bytes,
                         const std::string& where) {
  const Handle type(H5Dget_type(data.id()), H5Tclose);
  const H5T_class_t type_class = H5Tget_class(type.id());
  if (type_class != H5T_FLOAT && type_class != H5T_INTEGER) {
    throw Error(ErrorCode::kBadInput, kStage, where + " is not numeric");
  }
  CheckNumberSize(type.id(), where);
  const Handle space(H5Dget_space(data.id()), H5Sclose);
  const hssize_t count = H5Sget_simple_extent_npoints(space.id());
  if (count < 0) throw Error(ErrorCode::kBadInput, kStage, "cannot read the size of " + where);
  hsize_t file_bytes = 0;
  H5Fget_filesize(file_id, &file_bytes);
  const double declared_bytes = static_cast<double>(count) * static_cast<double>(value_bytes);
  if (declared_bytes > 64.0 * std::max<double>(static_cast<double>(file_bytes), 1 << 20)) {
    throw Error(ErrorCode::kBadInput, kStage,
                where + " declares " + std::to_string(count) + " values, more than the " +
                    std::to_string(file_bytes) + "-byte file can hold (damaged?)");
  }
  return static_cast<std::size_t>(count);
}

void ReadNumericInto(const Handle& data, hid_t memory_type, void* values, std::size_t count,
                     const std::string& where) {
  if (count > 0 && H5Dread(data.id(), memory_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, values) < 0) {
    CheckFiltersAvailable(data, where);
    throw Error(ErrorCode::kBadInput, kStage, "cannot read " + where + " (file truncated or damaged?)");
  }
}

template <typename T>
std::vector<T> ReadNumeric(hid_t file_id, const Handle& data, hid_t memory_type, const std::string& where) {
  std::vector<T> values(NumericCount(file_id, data, sizeof(T), where));
  ReadNumericInto(data, memory_type, values.data(), values.size(), where);
  return values;
}

}  // namespace

std::size_t File::NumericCount(const std::string& dataset, std::size_t value_bytes) const {
  return hdf5::NumericCount(handle_.id(), OpenDataset(dataset), value_bytes, Where(dataset));
}

namespace {

template <typename T>
void ReadIntoSpan(hid_t file_id, const Handle& data, hid_t memory_type, std::span<T> values,
                  const std::string& where) {
  if (NumericCount(file_id, data, sizeof(T), where) != values.size()) {
    throw Error(ErrorCode::kInternal, kStage, "buffer does not match the size of " + where);
  }
  ReadNumericInto(data, memory_type, values.data(), values.size(), where);
}

}  // namespace

void File::ReadInto(const std::string& dataset, std::span<double> values) const {
  ReadIntoSpan(handle_.id(), OpenDataset(dataset), H5T_NATIVE_DOUBLE, values, Where(dataset));
}

void File::ReadInto(const std::string& dataset, std::span<float> values) const {
  ReadIntoSpan(handle_.id(), OpenDataset(dataset), H5T_NATIVE_FLOAT, values, Where(dataset));
}

namespace {

// `count` values from `first` on, as libhdf5 reads them and as the file holds them at `offset`.
bool SameValuesInFile(const Handle& data, const std::filesystem::path& path, std::uint64_t offset,
                      hsize_t first, hsize_t count) {
  std::vector<float> read(count), stored(count);
  const Handle file_space(H5Dget_space(data.id()), H5Sclose);
  const Handle memory_space(H5Screate_simple(1, &count, nullptr), H5Sclose);
  if (H5Sselect_hyperslab(file_space.id(), H5S_SELECT_SET, &first, nullptr, &count, nullptr) < 0 ||
      H5Dread(data.id(), H5T_NATIVE_FLOAT, memory_space.id(), file_space.id(), H5P_DEFAULT, read.data()) < 0)
    return false;
  const int fd = open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) return false;
  const auto bytes = static_cast<ssize_t>(count * sizeof(float));
  const bool got = pread(fd, stored.data(), static_cast<std::size_t>(bytes),
                         static_cast<off_t>(offset + first * sizeof(float))) == bytes;
  close(fd);
  return got && std::memcmp(read.data(), stored.data(), static_cast<std::size_t>(bytes)) == 0;
}

}  // namespace

std::optional<FileExtent> File::ContiguousFloat32Extent(const std::string& dataset) const {
  if (image_ || std::endian::native != std::endian::little) return std::nullopt;
  const Handle data = OpenDataset(dataset);
  const Handle type(H5Dget_type(data.id()), H5Tclose);
  const Handle creation(H5Dget_create_plist(data.id()), H5Pclose);
  const Handle space(H5Dget_space(data.id()), H5Sclose);
  if (H5Tequal(type.id(), H5T_IEEE_F32LE) <= 0 || !creation.valid() ||
      H5Pget_layout(creation.id()) != H5D_CONTIGUOUS || H5Pget_external_count(creation.id()) != 0 ||
      H5Sget_simple_extent_ndims(space.id()) != 1)
    return std::nullopt;
  const std::size_t count = hdf5::NumericCount(handle_.id(), data, sizeof(float), Where(dataset));
  // libhdf5 1.10 gives the address from the file's start, user block included.
  const haddr_t offset = H5Dget_offset(data.id());
  std::error_code error;
  const std::uintmax_t file_bytes = std::filesystem::file_size(path_, error);
  if (count == 0 || offset == HADDR_UNDEF || offset % alignof(float) != 0 || error ||
      H5Dget_storage_size(data.id()) != count * sizeof(float) || offset + count * sizeof(float) > file_bytes)
    return std::nullopt;
  const hsize_t probe = std::min<hsize_t>(count, 1024);
  if (!SameValuesInFile(data, path_, offset, 0, probe) ||
      !SameValuesInFile(data, path_, offset, count - probe, probe))
    return std::nullopt;
  return FileExtent{.offset = offset, .count = count};
}

std::vector<double> File::ReadDoubles(const std::string& dataset) const {
  return ReadNumeric<double>(handle_.id(), OpenDataset(dataset), H5T_NATIVE_DOUBLE, Where(dataset));
}

std::vector<float> File::ReadFloats(const std::string& dataset) const {
  return ReadNumeric<float>(handle_.id(), OpenDataset(dataset), H5T_NATIVE_FLOAT, Where(dataset));
}

}  // namespace arcwheel::hdf5
