#pragma once
// The two halves of reading an HDF5 scan of either kind (not installed; shared by hdf5_reader.cc
// and profile_reader.cc): what the child process that guards against libhdf5 crashing reads into
// shared arrays (hdf5::ReadInChildProcess), and how the parent makes the scan from them. `handed`
// is ReadInChildProcess's answer: false, the parent reads the whole file itself. One child serves
// both kinds, so that `process` opens a file it has not yet seen in one child, not two.

#include "acquisition/profile_scan.h"
#include "acquisition/scan_reader.h"
#include "core/hdf5.h"

namespace arcwheel::acquisition::internal {

// formats.md 2.1: /scan and its columns.
void ReadHelixInChild(const hdf5::File& file, const ReadOptions& options, hdf5::SharedArrays& shared);
[[nodiscard]] Scan HelixFromChild(const hdf5::File& file, hdf5::SharedArrays& arrays, bool handed,
                                  const ReadOptions& options);

// The contract's line-profile layout: /profile.
void ReadProfileInChild(const hdf5::File& file, hdf5::SharedArrays& shared);
[[nodiscard]] ProfileScan ProfileFromChild(const hdf5::File& file, hdf5::SharedArrays& arrays, bool handed,
                                           const ScanSettingsFile* settings);

}  // namespace arcwheel::acquisition::internal
