#pragma once
// Readers for the raw scan layouts of formats.md section 2.
//
// Every reader folds the invalid-sample markers into NaN in Scan::z_mm (NaN, the
// `invalid_value` attribute compared in the file's own type, values outside
// range_min_mm/range_max_mm, and in CSV empty cells and sensor alarm words such as
// `-FFFFFFF` or `ALARM`), then runs ValidateScan(). Anything else that is wrong throws
// Error{kBadInput} (or kIo when the file cannot be opened) naming the file and the line or
// dataset.

#include <filesystem>
#include <functional>

#include "acquisition/scan.h"
#include "core/hdf5.h"

namespace arcwheel::acquisition {

struct ScanSettingsFile;  // acquisition/scan_settings.h

struct ReadOptions {
  // float32 readings stay float32 (Scan::z_float_mm): half the memory, the same results.
  bool keep_float32 = false;
  // Work for this process while the file is read: called once, while a child process reads an
  // HDF5 file (after its fork, so it may start threads), else just before the read.
  std::function<void()> while_reading;
  // formats.md 2.4: the settings from outside the file (`--scan-settings`), merged into the file's
  // own before the scan is checked (ApplyScanSettings); null: none. Not owned.
  const ScanSettingsFile* settings = nullptr;
};

// By the format the file name selects (scan_format.h, case-insensitive): .h5/.hdf5 -> ReadHdf5Scan,
// .csv/.txt -> ReadCsvScan; else Error{kBadInput}.
[[nodiscard]] Scan ReadScan(const std::filesystem::path& path, const ReadOptions& options = {});

// formats.md 2.1: group /scan, dataset /scan/z, optional /scan/t, /scan/angle, /scan/y. The data
// are read once, in a child process that guards against libhdf5 crashing on a damaged file
// (hdf5::ReadInChildProcess).
[[nodiscard]] Scan ReadHdf5Scan(const std::filesystem::path& path, const ReadOptions& options = {});

// formats.md 2.2: `# key: value` lines, a header row, separators , ; or tab, decimal point.
[[nodiscard]] Scan ReadCsvScan(const std::filesystem::path& path, const ReadOptions& options = {});
// The same from text already in memory; `name` stands for the file in messages.
[[nodiscard]] Scan ParseCsvScan(std::string text, const std::string& name, const ReadOptions& options = {});

// formats.md 2.1 from an open file (e.g. an in-memory image, hdf5::File::OpenImage).
[[nodiscard]] Scan ReadHdf5Scan(const hdf5::File& file, const ReadOptions& options = {});

}  // namespace arcwheel::acquisition
