// arcwheel::hdf5's reads of attributes: numbers, text (fixed or variable length, any padding) and
// the names of an object's attributes.
#include <hdf5.h>

#include <algorithm>
#include <charconv>
#include <cstddef>
#include <exception>
#include <optional>
#include <string>
#include <vector>

#include "core/error.h"
#include "core/hdf5.h"
#include "core/hdf5_impl.h"

namespace arcwheel::hdf5 {

using namespace internal;

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

}  // namespace arcwheel::hdf5
