#pragma once
// What the sources of arcwheel::hdf5 (core/hdf5*.cc) share. Not installed.

#include <hdf5.h>

#include <string>

namespace arcwheel::hdf5::internal {

inline constexpr const char* kStage = "hdf5";

// A damaged header can give a number any byte size, and HDF5 then allocates conversion buffers of
// that size per value: numbers are 1 to 16 bytes (long double), nothing else is read. Throws
// Error{kBadInput} naming `what` otherwise (core/hdf5_read.cc).
void CheckNumberSize(hid_t type, const std::string& what);

}  // namespace arcwheel::hdf5::internal
