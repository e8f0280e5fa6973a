// Variable-length strings and sequences in HDF5 are stored as references, (length, address of a
// global heap collection, object index), to objects in global heap collections. libhdf5 1.10.8
// trusts both sides: a collection holding an object of size 0 makes it loop for ever while
// loading the collection, an index the collection does not hold makes it read through a null
// pointer, and an object larger than the reference says overruns the buffer it is copied into.
// So before the library reads a variable-length attribute or dataset, the references are read as stored
// (a conversion registered below leaves them unfollowed), and each is checked
// against the collection it names, walked the way the library walks it.

#include <hdf5.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "core/error.h"
#include "core/hdf5.h"

namespace arcwheel::hdf5 {
namespace {

constexpr const char* kHdf5HeapStage = "hdf5";

// A soft conversion from a variable-length type to an opaque one of the same size: the stored
// reference bytes stay as they are, and the library follows nothing. (The same size matters: a
// wider destination makes the library grow elements in place, which overruns its buffer when a
// damaged compound type declares overlapping members.)
herr_t KeepStoredReference(hid_t source, hid_t destination, H5T_cdata_t* cdata, size_t /*count*/,
                           size_t /*stride*/, size_t /*background_stride*/, void* /*buffer*/,
                           void* /*background*/, hid_t /*transfer*/) {
  if (cdata->command == H5T_CONV_INIT) {
    const H5T_class_t source_class = H5Tget_class(source);
    const bool variable =
        source_class == H5T_VLEN || (source_class == H5T_STRING && H5Tis_variable_str(source) > 0);
    cdata->need_bkg = H5T_BKG_NO;
    return variable && H5Tget_size(destination) == H5Tget_size(source) ? 0 : -1;
  }
  return 0;
}

void RegisterKeepStoredReference() {
  static const bool registered = [] {
    // A soft conversion applies to every pair of these classes; the types only name the classes.
    const Handle sequence(H5Tvlen_create(H5T_NATIVE_UCHAR), H5Tclose);
    const Handle text(H5Tcopy(H5T_C_S1), H5Tclose);
    H5Tset_size(text.id(), H5T_VARIABLE);
    const Handle opaque(H5Tcreate(H5T_OPAQUE, 16), H5Tclose);
    return H5Tregister(H5T_PERS_SOFT, "arcwheel stored sequence", sequence.id(), opaque.id(),
                       KeepStoredReference) >= 0 &&
           H5Tregister(H5T_PERS_SOFT, "arcwheel stored string", text.id(), opaque.id(),
                       KeepStoredReference) >= 0;
  }();
  if (!registered)
    throw Error(ErrorCode::kInternal, kHdf5HeapStage, "cannot register the stored-reference conversion");
}

// Little-endian unsigned field; UINT64_MAX when it does not fit 64 bits.
uint64_t Unsigned(const unsigned char* bytes, size_t size) {
  uint64_t value = 0;
  for (size_t k = 0; k < size; ++k) {
    if (k >= 8) {
      if (bytes[k] != 0) return UINT64_MAX;
    } else {
      value |= uint64_t{bytes[k]} << (8 * k);
    }
  }
  return value;
}

uint64_t Unsigned(std::string_view bytes, uint64_t at, size_t size) {
  return Unsigned(reinterpret_cast<const unsigned char*>(bytes.data() + at), size);
}

// H5HG_ALIGN, wrapping as the library's size_t arithmetic does.
uint64_t AlignTo8(uint64_t x) { return 8 * ((x + 7) / 8); }

struct StoredReference {
  uint64_t length = 0;  // elements (characters for a string)
  uint64_t address = 0;
  uint64_t index = 0;
};

// What would go wrong in libhdf5 1.10.8 reading `reference` from `collection` (its bytes from its
// address on, as many as the file has), or nothing. `expected_bytes` is what the reference holds.
std::optional<std::string> ReferenceProblem(std::string_view collection, const StoredReference& reference,
                                            uint64_t expected_bytes, size_t length_size) {
  const std::string at = "the global heap at byte " + std::to_string(reference.address);
  const uint64_t collection_header = AlignTo8(4 + 1 + 3 + length_size);
  const uint64_t object_header = 2 + 2 + 4 + length_size;
  if (collection.size() < collection_header || collection.substr(0, 4) != "GCOL" || collection[4] != 1) {
    return "refers to " + at + ", where there is none";
  }
  const uint64_t size = Unsigned(collection, 8, length_size);
  if (size > collection.size()) return at + " runs past the end of the file";
  std::optional<uint64_t> object_size;
  // As the library loads a collection: step from object to object by each one's size.
  for (uint64_t p = collection_header; p < size && size - p >= object_header;) {
    const uint64_t id = Unsigned(collection, p, 2);
    const uint64_t declared = Unsigned(collection, p + 8, length_size);
    const uint64_t step = id > 0 ? object_header + AlignTo8(declared) : declared;
    if (step == 0 || step > size - p) {
      return at + " is damaged (object " + std::to_string(id) + " at byte " + std::to_string(p) +
             " declares " + std::to_string(declared) + " bytes)";
    }
    if (id > 0 && id == reference.index) object_size = declared;
    p += step;
  }
  if (!object_size)
    return "refers to object " + std::to_string(reference.index) + " of " + at + ", which has none";
  if (*object_size != expected_bytes) {
    return "refers to " + std::to_string(expected_bytes) + " bytes in object " +
           std::to_string(reference.index) + " of " + at + ", which holds " + std::to_string(*object_size);
  }
  return std::nullopt;
}

// Bytes per stored element of a variable-length type: its base type's, or one per character.
size_t StoredElementBytes(hid_t stored_type) {
  if (H5Tget_class(stored_type) == H5T_STRING) return 1;
  const Handle base(H5Tget_super(stored_type), H5Tclose);
  return base.valid() ? H5Tget_size(base.id()) : 0;
}

}  // namespace

std::string File::ReadRawBytes(uint64_t address, uint64_t size) const {
  hsize_t userblock = 0;
  const Handle creation(H5Fget_create_plist(handle_.id()), H5Pclose);
  if (!creation.valid() || H5Pget_userblock(creation.id(), &userblock) < 0) return {};
  if (address > UINT64_MAX - userblock) return {};
  const uint64_t start = userblock + address;
  if (image_) {
    if (start >= image_->size()) return {};
    return image_->substr(start, std::min<uint64_t>(size, image_->size() - start));
  }
  std::error_code error;
  const uint64_t file_size = std::filesystem::file_size(path_, error);
  if (error || start >= file_size) return {};
  std::string bytes(std::min<uint64_t>(size, file_size - start), '\0');
  std::ifstream in(path_, std::ios::binary);
  in.seekg(static_cast<std::streamoff>(start));
  in.read(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  bytes.resize(in ? bytes.size() : static_cast<size_t>(std::max<std::streamsize>(in.gcount(), 0)));
  return bytes;
}

void File::CheckHeapReferences(hid_t object, hid_t stored_type, const std::string& what,
                               const char* member) const {
  RegisterKeepStoredReference();
  size_t address_size = 0;
  size_t length_size = 0;
  const Handle creation(H5Fget_create_plist(handle_.id()), H5Pclose);
  if (!creation.valid() || H5Pget_sizes(creation.id(), &address_size, &length_size) < 0 ||
      address_size == 0 || address_size > 16 || length_size == 0 || length_size > 16) {
    throw Error(ErrorCode::kBadInput, kHdf5HeapStage,
                "'" + path_.string() + "' declares invalid address or length sizes");
  }
  const bool dataset = H5Iget_type(object) == H5I_DATASET;
  const Handle space(dataset ? H5Dget_space(object) : H5Aget_space(object), H5Sclose);
  const hssize_t elements = H5Sget_simple_extent_npoints(space.id());
  if (elements < 1 || elements > (1 << 16)) {
    throw Error(ErrorCode::kBadInput, kHdf5HeapStage,
                what + " holds " + std::to_string(elements) + " elements");
  }
  // As stored: 4 bytes of length, the address of a collection, 4 bytes of object index.
  const size_t stored_bytes = 4 + address_size + 4;
  const Handle opaque(H5Tcreate(H5T_OPAQUE, stored_bytes), H5Tclose);
  Handle memory_type;
  if (member != nullptr) {
    memory_type = Handle(H5Tcreate(H5T_COMPOUND, stored_bytes), H5Tclose);
    H5Tinsert(memory_type.id(), member, 0, opaque.id());
  } else {
    memory_type = Handle(H5Tcopy(opaque.id()), H5Tclose);
  }
  std::vector<unsigned char> stored(static_cast<size_t>(elements) * stored_bytes);
  const auto read = [&] {
    return dataset ? H5Dread(object, memory_type.id(), H5S_ALL, H5S_ALL, H5P_DEFAULT, stored.data())
                   : H5Aread(object, memory_type.id(), stored.data());
  };
  if (!memory_type.valid() || read() < 0) {
    throw Error(ErrorCode::kBadInput, kHdf5HeapStage, "cannot read the stored references of " + what);
  }
  const size_t element_bytes = StoredElementBytes(stored_type);
  for (hssize_t e = 0; e < elements; ++e) {
    const unsigned char* bytes = stored.data() + static_cast<size_t>(e) * stored_bytes;
    const StoredReference reference{.length = Unsigned(bytes, 4),
                                    .address = Unsigned(bytes + 4, address_size),
                                    .index = Unsigned(bytes + 4 + address_size, 4)};
    if (reference.address == 0) continue;  // an empty value: the library reads nothing
    const std::string header = ReadRawBytes(reference.address, 4 + 1 + 3 + 16);
    const uint64_t declared = header.size() >= 8 + length_size ? Unsigned(header, 8, length_size) : 0;
    // The collection as far as the file has it (never more than the file).
    const std::string collection =
        ReadRawBytes(reference.address, std::max<uint64_t>(declared, header.size()));
    const uint64_t expected_bytes = element_bytes == 0 || reference.length > UINT64_MAX / element_bytes
                                        ? UINT64_MAX
                                        : reference.length * element_bytes;
    if (const auto problem = ReferenceProblem(collection, reference, expected_bytes, length_size)) {
      throw Error(ErrorCode::kBadInput, kHdf5HeapStage, what + " " + *problem + " (damaged?)");
    }
  }
}

}  // namespace arcwheel::hdf5
