#include "core/hdf5.h"

#include <algorithm>
#include <utility>

#include "core/error.h"

namespace arcwheel::hdf5 {
namespace {

constexpr const char* kStage = "hdf5";

void SilenceHdf5ErrorStack() {
  static const bool silenced = [] {
    H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
    return true;
  }();
  (void)silenced;
}

}  // namespace

Handle& Handle::operator=(Handle&& other) noexcept {
  if (this != &other) {
    if (valid() && closer_ != nullptr) closer_(id_);
    id_ = std::exchange(other.id_, -1);
    closer_ = other.closer_;
  }
  return *this;
}

Handle::~Handle() {
  if (valid() && closer_ != nullptr) closer_(id_);
}

File File::OpenReadOnly(const std::filesystem::path& path) {
  SilenceHdf5ErrorStack();
  if (!std::filesystem::exists(path)) {
    throw Error(ErrorCode::kIo, kStage, "'" + path.string() + "' does not exist");
  }
  if (H5Fis_hdf5(path.c_str()) <= 0) {
    throw Error(ErrorCode::kBadInput, kStage,
                "'" + path.string() + "' is not an HDF5 file (or is truncated)");
  }
  const hid_t id = H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  if (id < 0) {
    throw Error(ErrorCode::kBadInput, kStage, "cannot open '" + path.string() + "' (damaged or truncated?)");
  }
  return File(Handle(id, H5Fclose), path);
}

File File::OpenImage(const void* data, size_t size, const std::string& name) {
  SilenceHdf5ErrorStack();
  const Handle access(H5Pcreate(H5P_FILE_ACCESS), H5Pclose);
  // The core driver without a backing store reads the image from memory only.
  if (size == 0 || H5Pset_fapl_core(access.id(), 1 << 16, 0) < 0 ||
      H5Pset_file_image(access.id(), const_cast<void*>(data), size) < 0) {
    throw Error(ErrorCode::kBadInput, kStage, "'" + name + "' is not an HDF5 file image");
  }
  const hid_t id = H5Fopen(name.c_str(), H5F_ACC_RDONLY, access.id());
  if (id < 0) throw Error(ErrorCode::kBadInput, kStage, "'" + name + "' is not an HDF5 file (or is truncated)");
  return File(Handle(id, H5Fclose), name);
}

File File::Create(const std::filesystem::path& path) {
  SilenceHdf5ErrorStack();
  const hid_t id = H5Fcreate(path.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
  if (id < 0) throw Error(ErrorCode::kIo, kStage, "cannot create '" + path.string() + "'");
  return File(Handle(id, H5Fclose), path);
}

std::string File::Where(const std::string& object) const {
  return "'" + path_.string() + "' " + object;
}

bool File::HasObject(const std::string& name) const {
  // Walk the path so that a missing parent group answers false instead of failing.
  std::string partial;
  size_t start = 1;
  while (start <= name.size()) {
    const size_t slash = name.find('/', start);
    partial = name.substr(0, slash);
    if (H5Lexists(handle_.id(), partial.c_str(), H5P_DEFAULT) <= 0) return false;
    if (slash == std::string::npos) break;
    start = slash + 1;
  }
  return true;
}

void File::CreateGroup(const std::string& name) {
  const Handle creation(H5Pcreate(H5P_GROUP_CREATE), H5Pclose);
  H5Pset_obj_track_times(creation.id(), 0);
  Handle group(H5Gcreate2(handle_.id(), name.c_str(), H5P_DEFAULT, creation.id(), H5P_DEFAULT), H5Gclose);
  if (!group.valid()) throw Error(ErrorCode::kIo, kStage, "cannot create group " + Where(name));
}

Handle File::OpenDataset(const std::string& dataset) const {
  if (!HasObject(dataset)) throw Error(ErrorCode::kBadInput, kStage, Where(dataset) + " is missing");
  Handle handle(H5Dopen2(handle_.id(), dataset.c_str(), H5P_DEFAULT), H5Dclose);
  if (!handle.valid()) throw Error(ErrorCode::kBadInput, kStage, Where(dataset) + " is not a dataset");
  return handle;
}

std::vector<hsize_t> File::Shape(const std::string& dataset) const {
  const Handle data = OpenDataset(dataset);
  const Handle space(H5Dget_space(data.id()), H5Sclose);
  const int rank = H5Sget_simple_extent_ndims(space.id());
  if (rank < 0) throw Error(ErrorCode::kBadInput, kStage, "cannot read the shape of " + Where(dataset));
  std::vector<hsize_t> dims(static_cast<size_t>(rank));
  H5Sget_simple_extent_dims(space.id(), dims.data(), nullptr);
  return dims;
}

H5T_class_t File::ElementClass(const std::string& dataset) const {
  const Handle data = OpenDataset(dataset);
  const Handle type(H5Dget_type(data.id()), H5Tclose);
  return H5Tget_class(type.id());
}

size_t File::ElementSize(const std::string& dataset) const {
  const Handle data = OpenDataset(dataset);
  const Handle type(H5Dget_type(data.id()), H5Tclose);
  return H5Tget_size(type.id());
}

namespace {

template <typename T>
std::vector<T> ReadNumeric(hid_t file_id, const Handle& data, hid_t memory_type, const std::string& where) {
  const Handle type(H5Dget_type(data.id()), H5Tclose);
  const H5T_class_t type_class = H5Tget_class(type.id());
  if (type_class != H5T_FLOAT && type_class != H5T_INTEGER) {
    throw Error(ErrorCode::kBadInput, kStage, where + " is not numeric");
  }
  const Handle space(H5Dget_space(data.id()), H5Sclose);
  const hssize_t count = H5Sget_simple_extent_npoints(space.id());
  if (count < 0) throw Error(ErrorCode::kBadInput, kStage, "cannot read the size of " + where);
  // A damaged header can declare any size: refuse more values than the file could hold even
  // compressed 64 to 1, rather than trying to allocate them.
  hsize_t file_bytes = 0;
  H5Fget_filesize(file_id, &file_bytes);
  const double declared_bytes = static_cast<double>(count) * static_cast<double>(sizeof(T));
  if (declared_bytes > 64.0 * std::max<double>(static_cast<double>(file_bytes), 1 << 20)) {
    throw Error(ErrorCode::kBadInput, kStage,
                where + " declares " + std::to_string(count) + " values, more than the " + std::to_string(file_bytes) +
                    "-byte file can hold (damaged?)");
  }
  std::vector<T> values(static_cast<size_t>(count));
  if (count > 0 &&
      H5Dread(data.id(), memory_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, values.data()) < 0) {
    throw Error(ErrorCode::kBadInput, kStage,
                "cannot read " + where + " (file truncated or damaged?)");
  }
  return values;
}

}  // namespace

std::vector<double> File::ReadDoubles(const std::string& dataset) const {
  return ReadNumeric<double>(handle_.id(), OpenDataset(dataset), H5T_NATIVE_DOUBLE, Where(dataset));
}

std::vector<float> File::ReadFloats(const std::string& dataset) const {
  return ReadNumeric<float>(handle_.id(), OpenDataset(dataset), H5T_NATIVE_FLOAT, Where(dataset));
}

namespace {

void WriteDataset(hid_t file, const std::string& name, hid_t file_type, hid_t memory_type,
                  const void* data, const std::vector<hsize_t>& shape, const std::string& where) {
  const Handle space(H5Screate_simple(static_cast<int>(shape.size()), shape.data(), nullptr), H5Sclose);
  // No modification times: the same data give byte-identical files (and SHA-256s).
  const Handle creation(H5Pcreate(H5P_DATASET_CREATE), H5Pclose);
  H5Pset_obj_track_times(creation.id(), 0);
  const Handle dataset(H5Dcreate2(file, name.c_str(), file_type, space.id(), H5P_DEFAULT,
                                  creation.id(), H5P_DEFAULT),
                       H5Dclose);
  if (!dataset.valid() ||
      H5Dwrite(dataset.id(), memory_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, data) < 0) {
    throw Error(ErrorCode::kIo, kStage, "cannot write " + where + " (disk full?)");
  }
}

hsize_t Product(const std::vector<hsize_t>& shape) {
  hsize_t n = 1;
  for (const hsize_t d : shape) n *= d;
  return n;
}

}  // namespace

void File::WriteDoubles(const std::string& dataset, const std::vector<double>& values,
                        const std::vector<hsize_t>& shape) {
  if (Product(shape) != values.size()) {
    throw Error(ErrorCode::kInternal, kStage, "shape does not match data for " + Where(dataset));
  }
  WriteDataset(handle_.id(), dataset, H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, values.data(), shape, Where(dataset));
}

void File::WriteFloats(const std::string& dataset, const std::vector<float>& values,
                       const std::vector<hsize_t>& shape) {
  if (Product(shape) != values.size()) {
    throw Error(ErrorCode::kInternal, kStage, "shape does not match data for " + Where(dataset));
  }
  WriteDataset(handle_.id(), dataset, H5T_IEEE_F32LE, H5T_NATIVE_FLOAT, values.data(), shape, Where(dataset));
}

void File::WriteInts(const std::string& dataset, const std::vector<int>& values,
                     const std::vector<hsize_t>& shape) {
  if (Product(shape) != values.size()) {
    throw Error(ErrorCode::kInternal, kStage, "shape does not match data for " + Where(dataset));
  }
  WriteDataset(handle_.id(), dataset, H5T_STD_I32LE, H5T_NATIVE_INT, values.data(), shape, Where(dataset));
}

bool File::HasAttribute(const std::string& object, const std::string& name) const {
  if (object != "/" && !HasObject(object)) return false;
  return H5Aexists_by_name(handle_.id(), object.c_str(), name.c_str(), H5P_DEFAULT) > 0;
}

std::optional<double> File::ReadAttributeDouble(const std::string& object, const std::string& name) const {
  if (!HasAttribute(object, name)) return std::nullopt;
  const Handle attribute(H5Aopen_by_name(handle_.id(), object.c_str(), name.c_str(), H5P_DEFAULT, H5P_DEFAULT),
                         H5Aclose);
  const Handle type(H5Aget_type(attribute.id()), H5Tclose);
  const H5T_class_t type_class = H5Tget_class(type.id());
  if (type_class == H5T_STRING) {
    // Some tools write numbers as strings; accept them only if they parse completely.
    const auto text = ReadAttributeString(object, name);
    try {
      size_t used = 0;
      const double value = std::stod(*text, &used);
      if (used == text->size()) return value;
    } catch (const std::exception&) {
    }
    throw Error(ErrorCode::kBadInput, kStage,
                "attribute '" + name + "' on " + Where(object) + " is not a number: '" + *text + "'");
  }
  if (type_class != H5T_FLOAT && type_class != H5T_INTEGER) {
    throw Error(ErrorCode::kBadInput, kStage, "attribute '" + name + "' on " + Where(object) + " is not numeric");
  }
  const Handle space(H5Aget_space(attribute.id()), H5Sclose);
  if (H5Sget_simple_extent_npoints(space.id()) != 1) {
    throw Error(ErrorCode::kBadInput, kStage,
                "attribute '" + name + "' on " + Where(object) + " must hold one value");
  }
  double value = 0.0;
  if (H5Aread(attribute.id(), H5T_NATIVE_DOUBLE, &value) < 0) {
    throw Error(ErrorCode::kBadInput, kStage, "cannot read attribute '" + name + "' on " + Where(object));
  }
  return value;
}

std::optional<std::string> File::ReadAttributeString(const std::string& object, const std::string& name) const {
  if (!HasAttribute(object, name)) return std::nullopt;
  const Handle attribute(H5Aopen_by_name(handle_.id(), object.c_str(), name.c_str(), H5P_DEFAULT, H5P_DEFAULT),
                         H5Aclose);
  const Handle type(H5Aget_type(attribute.id()), H5Tclose);
  const H5T_class_t type_class = H5Tget_class(type.id());
  if (type_class == H5T_FLOAT || type_class == H5T_INTEGER) {
    double value = 0.0;
    H5Aread(attribute.id(), H5T_NATIVE_DOUBLE, &value);
    std::string text = std::to_string(value);
    return text;
  }
  if (type_class != H5T_STRING) {
    throw Error(ErrorCode::kBadInput, kStage, "attribute '" + name + "' on " + Where(object) + " is not text");
  }
  if (H5Tis_variable_str(type.id()) > 0) {
    const Handle memory_type(H5Tcopy(H5T_C_S1), H5Tclose);
    H5Tset_size(memory_type.id(), H5T_VARIABLE);
    char* text = nullptr;
    if (H5Aread(attribute.id(), memory_type.id(), &text) < 0 || text == nullptr) {
      throw Error(ErrorCode::kBadInput, kStage, "cannot read attribute '" + name + "' on " + Where(object));
    }
    std::string result(text);
    H5free_memory(text);
    return result;
  }
  const size_t size = H5Tget_size(type.id());
  std::string buffer(size, '\0');
  const Handle memory_type(H5Tcopy(H5T_C_S1), H5Tclose);
  H5Tset_size(memory_type.id(), size);
  if (H5Aread(attribute.id(), memory_type.id(), buffer.data()) < 0) {
    throw Error(ErrorCode::kBadInput, kStage, "cannot read attribute '" + name + "' on " + Where(object));
  }
  buffer.resize(buffer.find('\0') == std::string::npos ? buffer.size() : buffer.find('\0'));
  return buffer;
}

void File::WriteAttribute(const std::string& object, const std::string& name, double value) {
  const Handle space(H5Screate(H5S_SCALAR), H5Sclose);
  const Handle attribute(H5Acreate_by_name(handle_.id(), object.c_str(), name.c_str(), H5T_IEEE_F64LE,
                                           space.id(), H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT),
                         H5Aclose);
  if (!attribute.valid() || H5Awrite(attribute.id(), H5T_NATIVE_DOUBLE, &value) < 0) {
    throw Error(ErrorCode::kIo, kStage, "cannot write attribute '" + name + "' on " + Where(object));
  }
}

void File::WriteAttribute(const std::string& object, const std::string& name, const std::string& value) {
  const Handle type(H5Tcopy(H5T_C_S1), H5Tclose);
  H5Tset_size(type.id(), value.empty() ? 1 : value.size());
  H5Tset_strpad(type.id(), H5T_STR_NULLTERM);
  const Handle space(H5Screate(H5S_SCALAR), H5Sclose);
  const Handle attribute(H5Acreate_by_name(handle_.id(), object.c_str(), name.c_str(), type.id(), space.id(),
                                           H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT),
                         H5Aclose);
  const std::string padded = value.empty() ? std::string(1, '\0') : value;
  if (!attribute.valid() || H5Awrite(attribute.id(), type.id(), padded.data()) < 0) {
    throw Error(ErrorCode::kIo, kStage, "cannot write attribute '" + name + "' on " + Where(object));
  }
}

}  // namespace arcwheel::hdf5
