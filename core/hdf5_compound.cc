// arcwheel::hdf5's reads of compound types: a compound attribute's members, and a compound
// dataset read as a table of strings.
#include <hdf5.h>

#include <cstddef>
#include <cstring>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "core/error.h"
#include "core/hdf5.h"
#include "core/hdf5_impl.h"

namespace arcwheel::hdf5 {
namespace {

using namespace internal;

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

}  // namespace arcwheel::hdf5
