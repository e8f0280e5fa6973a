#include "core/hdf5.h"

#include <dlfcn.h>

#include <algorithm>
#include <charconv>
#include <cstddef>
#include <cstring>
#include <set>
#include <span>
#include <utility>

#include "core/error.h"

namespace arcwheel::hdf5 {
namespace {

constexpr const char* kStage = "hdf5";

// Debian 12's hdf5-plugin-lzf calls lzf_compress/lzf_decompress without declaring liblzf as a
// dependency, so libhdf5's dlopen of the plugin fails on an undefined symbol and an LZF dataset
// (h5py's own filter) cannot be read. Loading liblzf globally first lets the plugin resolve them;
// where liblzf is missing nothing changes, and such a file is refused naming the filter.
void LoadLzfForTheLzfPlugin() { (void)::dlopen("liblzf.so.1", RTLD_NOW | RTLD_GLOBAL); }

void SilenceHdf5ErrorStack() {
  static const bool silenced = [] {
    H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
    LoadLzfForTheLzfPlugin();
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
  if (id < 0)
    throw Error(ErrorCode::kBadInput, kStage, "'" + name + "' is not an HDF5 file (or is truncated)");
  File file(Handle(id, H5Fclose), name);
  file.image_ = std::make_shared<const std::string>(static_cast<const char*>(data), size);
  return file;
}

File File::Create(const std::filesystem::path& path) {
  SilenceHdf5ErrorStack();
  const hid_t id = H5Fcreate(path.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
  if (id < 0) throw Error(ErrorCode::kIo, kStage, "cannot create '" + path.string() + "'");
  return File(Handle(id, H5Fclose), path);
}

std::string File::Where(const std::string& object) const {
  // Appended piece by piece: GCC 12 warns falsely (-Wrestrict) on "'" + std::string.
  std::string where(1, '\'');
  where += path_.string();
  where += "' ";
  where += object;
  return where;
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

// A damaged header can give a number any byte size, and HDF5 then allocates conversion buffers of
// that size per value: numbers are 1 to 16 bytes (long double), nothing else is read.
void CheckNumberSize(hid_t type, const std::string& what) {
  const size_t size = H5Tget_size(type);
  if (size == 0 || size > 16) {
    throw Error(ErrorCode::kBadInput, kStage,
                what + " has numbers of " + std::to_string(size) + " bytes (damaged?)");
  }
}

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

std::vector<double> File::ReadDoubles(const std::string& dataset) const {
  return ReadNumeric<double>(handle_.id(), OpenDataset(dataset), H5T_NATIVE_DOUBLE, Where(dataset));
}

std::vector<float> File::ReadFloats(const std::string& dataset) const {
  return ReadNumeric<float>(handle_.id(), OpenDataset(dataset), H5T_NATIVE_FLOAT, Where(dataset));
}

namespace {

void WriteDataset(hid_t file, const std::string& name, hid_t file_type, hid_t memory_type, const void* data,
                  const std::vector<hsize_t>& shape, const std::string& where) {
  const Handle space(H5Screate_simple(static_cast<int>(shape.size()), shape.data(), nullptr), H5Sclose);
  // No modification times: the same data give byte-identical files (and SHA-256s).
  const Handle creation(H5Pcreate(H5P_DATASET_CREATE), H5Pclose);
  H5Pset_obj_track_times(creation.id(), 0);
  const Handle dataset(
      H5Dcreate2(file, name.c_str(), file_type, space.id(), H5P_DEFAULT, creation.id(), H5P_DEFAULT),
      H5Dclose);
  if (!dataset.valid() || H5Dwrite(dataset.id(), memory_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, data) < 0) {
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
  WriteDataset(handle_.id(), dataset, H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, values.data(), shape,
               Where(dataset));
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

Handle File::OpenAttribute(const std::string& object, const std::string& name) const {
  return Handle(H5Aopen_by_name(handle_.id(), object.c_str(), name.c_str(), H5P_DEFAULT, H5P_DEFAULT),
                H5Aclose);
}

std::string File::AttributeWhere(const std::string& object, const std::string& name) const {
  return "attribute '" + name + "' on " + Where(object);
}

bool File::HasAttribute(const std::string& object, const std::string& name) const {
  if (object != "/" && !HasObject(object)) return false;
  return H5Aexists_by_name(handle_.id(), object.c_str(), name.c_str(), H5P_DEFAULT) > 0;
}

std::optional<double> File::ReadAttributeDouble(const std::string& object, const std::string& name) const {
  if (!HasAttribute(object, name)) return std::nullopt;
  const std::string where = AttributeWhere(object, name);
  const Handle attribute = OpenAttribute(object, name);
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
    throw Error(ErrorCode::kBadInput, kStage, where + " is not a number: '" + *text + "'");
  }
  if (type_class != H5T_FLOAT && type_class != H5T_INTEGER) {
    throw Error(ErrorCode::kBadInput, kStage, where + " is not numeric");
  }
  CheckNumberSize(type.id(), where);
  const Handle space(H5Aget_space(attribute.id()), H5Sclose);
  if (H5Sget_simple_extent_npoints(space.id()) != 1) {
    throw Error(ErrorCode::kBadInput, kStage, where + " must hold one value");
  }
  double value = 0.0;
  if (H5Aread(attribute.id(), H5T_NATIVE_DOUBLE, &value) < 0) {
    throw Error(ErrorCode::kBadInput, kStage, "cannot read " + where);
  }
  return value;
}

std::optional<std::string> File::ReadAttributeString(const std::string& object,
                                                     const std::string& name) const {
  if (!HasAttribute(object, name)) return std::nullopt;
  const std::string where = AttributeWhere(object, name);
  const Handle attribute = OpenAttribute(object, name);
  const Handle type(H5Aget_type(attribute.id()), H5Tclose);
  const H5T_class_t type_class = H5Tget_class(type.id());
  const Handle space(H5Aget_space(attribute.id()), H5Sclose);
  // Scalar or a one-element array (as MATLAB and some h5py scripts write): one value either way.
  const hssize_t count = H5Sget_simple_extent_npoints(space.id());
  if (count != 1) {
    throw Error(ErrorCode::kBadInput, kStage,
                where + " holds " + std::to_string(count) + " values; expected one");
  }
  if (type_class == H5T_FLOAT || type_class == H5T_INTEGER) {
    const std::optional<double> value = ReadAttributeDouble(object, name);
    char text[32];
    const auto end =
        std::to_chars(text, text + sizeof text, *value).ptr;  // shortest exact form: 3, not 3.000000
    return std::string(text, end);
  }
  if (type_class != H5T_STRING) {
    throw Error(ErrorCode::kBadInput, kStage, where + " is not text");
  }
  // The memory type keeps the stored character set: libhdf5 refuses to convert UTF-8 to ASCII.
  const H5T_cset_t charset = H5Tget_cset(type.id());
  if (H5Tis_variable_str(type.id()) > 0) {
    CheckHeapReferences(attribute.id(), type.id(), where);
    const Handle memory_type(H5Tcopy(H5T_C_S1), H5Tclose);
    H5Tset_size(memory_type.id(), H5T_VARIABLE);
    H5Tset_cset(memory_type.id(), charset);
    char* text = nullptr;
    if (H5Aread(attribute.id(), memory_type.id(), &text) < 0) {
      throw Error(ErrorCode::kBadInput, kStage, "cannot read " + where);
    }
    std::string result = text == nullptr ? std::string() : std::string(text);
    H5free_memory(text);
    return result;
  }
  const size_t size = H5Tget_size(type.id());
  if (size > (1U << 20)) {
    throw Error(ErrorCode::kBadInput, kStage,
                where + " declares " + std::to_string(size) + " bytes of text (damaged?)");
  }
  // Read the stored bytes as they are (a null-padded memory type of the same size and character
  // set: no conversion), then take off the padding the file declares. A null-terminated memory type
  // would make libhdf5 drop the last character of a full null-padded string to fit its terminator.
  std::string buffer(size, '\0');
  const Handle memory_type(H5Tcopy(H5T_C_S1), H5Tclose);
  H5Tset_size(memory_type.id(), size);
  H5Tset_cset(memory_type.id(), charset);
  H5Tset_strpad(memory_type.id(), H5T_STR_NULLPAD);
  if (H5Aread(attribute.id(), memory_type.id(), buffer.data()) < 0) {
    throw Error(ErrorCode::kBadInput, kStage, "cannot read " + where);
  }
  // Whether or not libhdf5 converted the padding on the way, the text ends at the first NUL and,
  // space-padded, before its trailing blanks.
  buffer.resize(std::min(buffer.size(), buffer.find('\0')));
  if (H5Tget_strpad(type.id()) == H5T_STR_SPACEPAD) {
    const size_t last = buffer.find_last_not_of(' ');
    buffer.resize(last == std::string::npos ? 0 : last + 1);
  }
  return buffer;
}

namespace {

herr_t CollectAttributeName(hid_t, const char* name, const H5A_info_t*, void* names) {
  static_cast<std::vector<std::string>*>(names)->emplace_back(name);
  return 0;
}

}  // namespace

std::vector<std::string> File::AttributeNames(const std::string& object) const {
  std::vector<std::string> names;
  if (object != "/" && !HasObject(object)) return names;
  // libhdf5 1.10.8 builds a table of all attributes to iterate, and if one of them fails to decode
  // it frees the half-built table through a null pointer. Looking up a name that is not there
  // decodes every attribute message the same way without that table: a damaged one fails here.
  if (H5Aexists_by_name(handle_.id(), object.c_str(), "\x01 no such attribute", H5P_DEFAULT) < 0) {
    throw Error(ErrorCode::kBadInput, kStage,
                "cannot list the attributes of " + Where(object) + " (damaged?)");
  }
  // Creation order is tracked only when the writer asked for it; name order always works.
  hsize_t position = 0;
  if (H5Aiterate_by_name(handle_.id(), object.c_str(), H5_INDEX_CRT_ORDER, H5_ITER_INC, &position,
                         CollectAttributeName, &names, H5P_DEFAULT) >= 0) {
    return names;
  }
  names.clear();
  position = 0;
  if (H5Aiterate_by_name(handle_.id(), object.c_str(), H5_INDEX_NAME, H5_ITER_INC, &position,
                         CollectAttributeName, &names, H5P_DEFAULT) < 0) {
    throw Error(ErrorCode::kBadInput, kStage, "cannot list the attributes of " + Where(object));
  }
  return names;
}

namespace {

// One member of a compound type read on its own: HDF5 converts a compound by member name, so a
// memory compound holding just that member picks it out of the stored one.
struct MemberReader {
  Handle memory_type;  // the one-member compound
  size_t element_size = 0;
  enum class Kind { kString, kVariableString, kNumber, kVariableNumbers } kind = Kind::kNumber;
  size_t count = 1;  // numbers per element for kNumber (an array member)
};

bool IsNumeric(hid_t type) {
  const H5T_class_t c = H5Tget_class(type);
  return c == H5T_INTEGER || c == H5T_FLOAT;
}

std::optional<MemberReader> MakeMemberReader(hid_t member_type, const char* member_name) {
  MemberReader reader;
  Handle value_type;
  const H5T_class_t member_class = H5Tget_class(member_type);
  if (member_class == H5T_STRING) {
    value_type = Handle(H5Tcopy(H5T_C_S1), H5Tclose);
    if (H5Tis_variable_str(member_type) > 0) {
      H5Tset_size(value_type.id(), H5T_VARIABLE);
      reader.kind = MemberReader::Kind::kVariableString;
      reader.element_size = sizeof(char*);
    } else {
      const size_t size = H5Tget_size(member_type);
      if (size == 0 || size > (1u << 16)) return std::nullopt;
      H5Tset_size(value_type.id(), size);
      reader.kind = MemberReader::Kind::kString;
      reader.element_size = size;
    }
  } else if (IsNumeric(member_type)) {
    value_type = Handle(H5Tcopy(H5T_NATIVE_DOUBLE), H5Tclose);
    reader.element_size = sizeof(double);
  } else if (member_class == H5T_ARRAY) {
    const Handle base(H5Tget_super(member_type), H5Tclose);
    const int rank = H5Tget_array_ndims(member_type);
    if (!base.valid() || !IsNumeric(base.id()) || rank < 1 || rank > 4) return std::nullopt;
    hsize_t dims[4] = {0, 0, 0, 0};
    H5Tget_array_dims2(member_type, dims);
    hsize_t count = 1;
    for (int k = 0; k < rank; ++k) count *= dims[k];
    if (count == 0 || count > (1u << 16)) return std::nullopt;
    value_type = Handle(H5Tarray_create2(H5T_NATIVE_DOUBLE, static_cast<unsigned>(rank), dims), H5Tclose);
    reader.count = static_cast<size_t>(count);
    reader.element_size = reader.count * sizeof(double);
  } else if (member_class == H5T_VLEN) {
    const Handle base(H5Tget_super(member_type), H5Tclose);
    if (!base.valid() || !IsNumeric(base.id())) return std::nullopt;
    value_type = Handle(H5Tvlen_create(H5T_NATIVE_DOUBLE), H5Tclose);
    reader.kind = MemberReader::Kind::kVariableNumbers;
    reader.element_size = sizeof(hvl_t);
  } else {
    return std::nullopt;
  }
  if (!value_type.valid()) return std::nullopt;
  reader.memory_type = Handle(H5Tcreate(H5T_COMPOUND, reader.element_size), H5Tclose);
  if (!reader.memory_type.valid() ||
      H5Tinsert(reader.memory_type.id(), member_name, 0, value_type.id()) < 0) {
    return std::nullopt;
  }
  return reader;
}

// The text of a string member read by `reader` into `element` (fixed: up to its first NUL).
std::string MemberString(const MemberReader& reader, const unsigned char* element) {
  if (reader.kind == MemberReader::Kind::kVariableString) {
    const char* text = *reinterpret_cast<char* const*>(element);
    return text == nullptr ? std::string() : std::string(text);
  }
  const auto* text = reinterpret_cast<const char*>(element);
  return std::string(text, strnlen(text, reader.element_size));
}

bool IsVariableLength(const MemberReader& reader) {
  return reader.kind == MemberReader::Kind::kVariableString ||
         reader.kind == MemberReader::Kind::kVariableNumbers;
}

// max_align_t storage for `elements` values of a member: pointers (variable-length) and doubles.
std::vector<std::max_align_t> MemberBuffer(const MemberReader& reader, hssize_t elements) {
  return std::vector<std::max_align_t>(
      (static_cast<size_t>(elements) * reader.element_size + sizeof(std::max_align_t) - 1) /
      sizeof(std::max_align_t));
}

// libhdf5 1.10.8 converts a compound by moving each member from its stored offset, trusting the
// stored layout: a damaged type whose member lies past the end of the compound makes it copy from
// outside its buffer. A layout written by the library has members inside the compound and apart.
void CheckCompoundLayout(hid_t type, const std::string& where) {
  const size_t size = H5Tget_size(type);
  const int members = H5Tget_nmembers(type);
  std::vector<std::pair<size_t, size_t>> spans;  // [offset, end) of each member
  for (int m = 0; m < members; ++m) {
    const Handle member_type(H5Tget_member_type(type, static_cast<unsigned>(m)), H5Tclose);
    const size_t offset = H5Tget_member_offset(type, static_cast<unsigned>(m));
    const size_t member_size = member_type.valid() ? H5Tget_size(member_type.id()) : 0;
    if (member_size == 0 || offset > size || member_size > size - offset) {
      throw Error(ErrorCode::kBadInput, kStage,
                  where + " has a member of " + std::to_string(member_size) + " bytes at byte " +
                      std::to_string(offset) + " of a compound of " + std::to_string(size) +
                      " bytes (damaged?)");
    }
    spans.emplace_back(offset, offset + member_size);
  }
  std::sort(spans.begin(), spans.end());
  for (size_t k = 1; k < spans.size(); ++k) {
    if (spans[k].first < spans[k - 1].second) {
      throw Error(
          ErrorCode::kBadInput, kStage,
          where + " has members overlapping at byte " + std::to_string(spans[k].first) + " (damaged?)");
    }
  }
}

}  // namespace

std::optional<File::Compound> File::ReadAttributeCompound(const std::string& object,
                                                          const std::string& name) const {
  if (!HasAttribute(object, name)) return std::nullopt;
  const std::string where = AttributeWhere(object, name);
  const Handle attribute = OpenAttribute(object, name);
  const Handle type(H5Aget_type(attribute.id()), H5Tclose);
  if (!attribute.valid() || !type.valid() || H5Tget_class(type.id()) != H5T_COMPOUND) {
    throw Error(ErrorCode::kBadInput, kStage, where + " is not a compound");
  }
  const Handle space(H5Aget_space(attribute.id()), H5Sclose);
  const hssize_t elements = H5Sget_simple_extent_npoints(space.id());
  if (elements < 1 || elements > (1 << 16)) {
    throw Error(ErrorCode::kBadInput, kStage, where + " holds " + std::to_string(elements) + " elements");
  }
  CheckCompoundLayout(type.id(), where);
  Compound result;
  std::set<std::string> names;
  const int members = H5Tget_nmembers(type.id());
  for (int m = 0; m < members; ++m) {
    char* raw_name = H5Tget_member_name(type.id(), static_cast<unsigned>(m));
    if (raw_name == nullptr) continue;
    const std::string member(raw_name);
    H5free_memory(raw_name);
    // The library converts by name: two members of one name would both be read into one.
    if (!names.insert(member).second) {
      throw Error(ErrorCode::kBadInput, kStage, where + " has two members named '" + member + "' (damaged?)");
    }
    const Handle member_type(H5Tget_member_type(type.id(), static_cast<unsigned>(m)), H5Tclose);
    const std::optional<MemberReader> reader = MakeMemberReader(member_type.id(), member.c_str());
    if (!reader) continue;
    if (IsVariableLength(*reader)) {
      CheckHeapReferences(attribute.id(), member_type.id(), "member '" + member + "' of " + where,
                          member.c_str());
    }
    std::vector<std::max_align_t> buffer = MemberBuffer(*reader, elements);
    if (H5Aread(attribute.id(), reader->memory_type.id(), buffer.data()) < 0) {
      throw Error(ErrorCode::kBadInput, kStage, "cannot read member '" + member + "' of " + where);
    }
    const auto* first = reinterpret_cast<const unsigned char*>(buffer.data());
    switch (reader->kind) {
      case MemberReader::Kind::kString:
      case MemberReader::Kind::kVariableString:
        result.strings[member] = MemberString(*reader, first);
        break;
      case MemberReader::Kind::kNumber: {
        const auto* values = reinterpret_cast<const double*>(first);
        result.numbers[member] = std::vector<double>(values, values + reader->count);
        break;
      }
      case MemberReader::Kind::kVariableNumbers: {
        const auto* sequence = reinterpret_cast<const hvl_t*>(first);
        const auto* values = static_cast<const double*>(sequence->p);
        result.numbers[member] =
            values == nullptr ? std::vector<double>() : std::vector<double>(values, values + sequence->len);
        break;
      }
    }
    if (IsVariableLength(*reader)) {
      H5Dvlen_reclaim(reader->memory_type.id(), space.id(), H5P_DEFAULT, buffer.data());
    }
  }
  return result;
}

std::vector<std::vector<std::string>> File::ReadStringTable(const std::string& dataset,
                                                            const std::vector<std::string>& columns) const {
  const std::string where = Where(dataset);
  const Handle data = OpenDataset(dataset);
  const Handle type(H5Dget_type(data.id()), H5Tclose);
  if (!type.valid() || H5Tget_class(type.id()) != H5T_COMPOUND) {
    throw Error(ErrorCode::kBadInput, kStage, where + " is not a table (a compound dataset)");
  }
  const Handle space(H5Dget_space(data.id()), H5Sclose);
  const hssize_t rows = H5Sget_simple_extent_npoints(space.id());
  if (H5Sget_simple_extent_ndims(space.id()) != 1 || rows < 0 || rows > (1 << 16)) {
    throw Error(ErrorCode::kBadInput, kStage,
                where + " must be a one-dimensional table of at most 65536 rows (damaged?)");
  }
  CheckCompoundLayout(type.id(), where);
  std::vector<std::vector<std::string>> table(static_cast<size_t>(rows),
                                              std::vector<std::string>(columns.size()));
  for (size_t c = 0; c < columns.size(); ++c) {
    const std::string column = "column '" + columns[c] + "' of " + where;
    const int index = H5Tget_member_index(type.id(), columns[c].c_str());
    if (index < 0) throw Error(ErrorCode::kBadInput, kStage, where + " has no column '" + columns[c] + "'");
    const Handle member_type(H5Tget_member_type(type.id(), static_cast<unsigned>(index)), H5Tclose);
    const std::optional<MemberReader> reader = MakeMemberReader(member_type.id(), columns[c].c_str());
    if (!reader || (reader->kind != MemberReader::Kind::kString &&
                    reader->kind != MemberReader::Kind::kVariableString)) {
      throw Error(ErrorCode::kBadInput, kStage, column + " is not text");
    }
    if (IsVariableLength(*reader))
      CheckHeapReferences(data.id(), member_type.id(), column, columns[c].c_str());
    std::vector<std::max_align_t> buffer = MemberBuffer(*reader, rows);
    if (rows > 0 &&
        H5Dread(data.id(), reader->memory_type.id(), H5S_ALL, H5S_ALL, H5P_DEFAULT, buffer.data()) < 0) {
      throw Error(ErrorCode::kBadInput, kStage, "cannot read " + column);
    }
    const auto* first = reinterpret_cast<const unsigned char*>(buffer.data());
    for (size_t r = 0; r < table.size(); ++r)
      table[r][c] = MemberString(*reader, first + r * reader->element_size);
    if (IsVariableLength(*reader) && rows > 0) {
      H5Dvlen_reclaim(reader->memory_type.id(), space.id(), H5P_DEFAULT, buffer.data());
    }
  }
  return table;
}

namespace {

struct LinkNames {
  std::vector<std::string> names;
  bool too_many = false;
};

herr_t CollectLinkName(hid_t, const char* name, const H5L_info_t*, void* data) {
  auto* links = static_cast<LinkNames*>(data);
  if (links->names.size() >= (1u << 16)) {
    links->too_many = true;
    return 1;  // stop
  }
  links->names.emplace_back(name);
  return 0;
}

}  // namespace

std::vector<std::string> File::DatasetNames(const std::string& group) const {
  if (group != "/" && !HasObject(group)) return {};
  const Handle handle(H5Gopen2(handle_.id(), group.c_str(), H5P_DEFAULT), H5Gclose);
  if (!handle.valid()) return {};
  LinkNames links;
  hsize_t position = 0;
  if (H5Literate(handle.id(), H5_INDEX_NAME, H5_ITER_INC, &position, CollectLinkName, &links) < 0 ||
      links.too_many) {
    throw Error(ErrorCode::kBadInput, kStage,
                "cannot list the members of " + Where(group) + (links.too_many ? " (more than 65536)" : ""));
  }
  std::vector<std::string> datasets;
  for (const std::string& name : links.names) {
    H5O_info_t info;
    if (H5Oget_info_by_name2(handle.id(), name.c_str(), &info, H5O_INFO_BASIC, H5P_DEFAULT) >= 0 &&
        info.type == H5O_TYPE_DATASET) {
      datasets.push_back(name);
    }
  }
  return datasets;
}

void File::WriteAttribute(const std::string& object, const std::string& name, double value) {
  const Handle space(H5Screate(H5S_SCALAR), H5Sclose);
  const Handle attribute(H5Acreate_by_name(handle_.id(), object.c_str(), name.c_str(), H5T_IEEE_F64LE,
                                           space.id(), H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT),
                         H5Aclose);
  if (!attribute.valid() || H5Awrite(attribute.id(), H5T_NATIVE_DOUBLE, &value) < 0) {
    throw Error(ErrorCode::kIo, kStage, "cannot write " + AttributeWhere(object, name));
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
    throw Error(ErrorCode::kIo, kStage, "cannot write " + AttributeWhere(object, name));
  }
}

}  // namespace arcwheel::hdf5
