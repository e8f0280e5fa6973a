// arcwheel::hdf5's handles and files: opening, creating, the objects in a file and their shapes.
// Numeric datasets are read in hdf5_read.cc, written (with attributes) in hdf5_write.cc;
// attributes are read in hdf5_attribute.cc, compounds and string tables in hdf5_compound.cc.
#include "core/hdf5.h"

#include <dlfcn.h>

#include <string>
#include <utility>
#include <vector>

#include "core/error.h"
#include "core/hdf5_impl.h"

namespace arcwheel::hdf5 {
namespace {

using namespace internal;

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

}  // namespace arcwheel::hdf5
