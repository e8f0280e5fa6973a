// arcwheel::hdf5's writes: numeric datasets (without modification times, so that the same data
// give byte-identical files) and attributes.
#include <hdf5.h>

#include <string>
#include <vector>

#include "core/error.h"
#include "core/hdf5.h"
#include "core/hdf5_impl.h"

namespace arcwheel::hdf5 {
namespace {

using namespace internal;

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
