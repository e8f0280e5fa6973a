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

#include "acquisition/scan.h"
#include "core/hdf5.h"

namespace arcwheel::acquisition {

// By extension: .h5/.hdf5 -> ReadHdf5Scan, .csv/.txt -> ReadCsvScan; else Error{kBadInput}.
[[nodiscard]] Scan ReadScan(const std::filesystem::path& path);

// formats.md 2.1: group /scan, dataset /scan/z, optional /scan/t, /scan/angle, /scan/y.
[[nodiscard]] Scan ReadHdf5Scan(const std::filesystem::path& path);

// formats.md 2.2: `# key: value` lines, a header row, separators , ; or tab, decimal point.
[[nodiscard]] Scan ReadCsvScan(const std::filesystem::path& path);
// The same from text already in memory; `name` stands for the file in messages.
[[nodiscard]] Scan ParseCsvScan(std::string text, const std::string& name);

// formats.md 2.1 from an open file (e.g. an in-memory image, hdf5::File::OpenImage).
[[nodiscard]] Scan ReadHdf5Scan(const hdf5::File& file);

}  // namespace arcwheel::acquisition
