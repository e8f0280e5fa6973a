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
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "acquisition/profile_scan.h"
#include "acquisition/scan.h"
#include "acquisition/scan_format.h"
#include "core/hdf5.h"

namespace arcwheel::acquisition {

struct ScanSettingsFile;  // acquisition/scan_settings.h

struct ReadOptions {
  // float32 readings stay float32 (Scan::z_float_mm): half the memory, the same results.
  bool keep_float32 = false;
  // Work for this process beside the parsing of a text file: called once, just before the read.
  // An HDF5 file's readers do not call it: they fork (no thread may be alive then), their child
  // takes milliseconds, and the one pass over the readings that follows takes both cores, which a
  // third thread would slow (at 1e8 samples the reading took 0.23 s with the input's SHA-256
  // beside it, 0.16 s without). The caller starts such work after an HDF5 file's read.
  std::function<void()> while_reading;
  // formats.md 2.4: the settings from outside the file (`--scan-settings`), merged into the file's
  // own before the scan is checked (ApplyScanSettings); null: none. Not owned.
  const ScanSettingsFile* settings = nullptr;
  // formats.md 2.4: the reader by name (`--format`, scan_format.h); empty: by the extension and a
  // sniff of the header.
  std::string format;
  // `--columns z=NAME[:UNIT],t=NAME[:UNIT],angle=NAME[:UNIT],y=NAME[:UNIT]`: which column of a
  // delimited file holds which quantity, by its header name, and in which unit (z, y: mm, um, nm;
  // t: s, ms, us; angle: deg, counts). Reads the file as `columns` unless `format` names a sensor's
  // layout, whose own choice of columns it then overrides. Empty: none.
  std::string columns;
};

// By the format that options.format names, or that the file's extension and a sniff of its header
// select (scan_format.h, ScanFormatOfContent): ReadHdf5Scan, ReadCsvScan or ReadSensorScan.
[[nodiscard]] Scan ReadScan(const std::filesystem::path& path, const ReadOptions& options = {});

// A scan of either kind, as `process` reads it: a line-profile scan (profile_scan.h) when
// options.format names a profile layout, or the extension and a sniff select one, or an HDF5 file
// (not forced to "hdf5") has a /profile group; else a point-sensor scan, as ReadScan reads it. An
// HDF5 file is opened in one child process for both, the kind and the data (ReadHdf5Scan).
// options.settings serves both kinds.
[[nodiscard]] std::variant<Scan, ProfileScan> ReadAnyScan(const std::filesystem::path& path,
                                                          const ReadOptions& options = {});

// formats.md 2.1: group /scan, dataset /scan/z, optional /scan/t, /scan/angle, /scan/y. The data
// are read once, in a child process that guards against libhdf5 crashing on a damaged file
// (hdf5::ReadInChildProcess).
[[nodiscard]] Scan ReadHdf5Scan(const std::filesystem::path& path, const ReadOptions& options = {});

// formats.md 2.2: `# key: value` lines, a header row, separators , ; or tab, decimal point.
[[nodiscard]] Scan ReadCsvScan(const std::filesystem::path& path, const ReadOptions& options = {});
// The same from text already in memory; `name` stands for the file in messages.
[[nodiscard]] Scan ParseCsvScan(std::string text, const std::string& name, const ReadOptions& options = {});

// formats.md 2.4: the sensors' own files. `format` is kSensorTool (Micro-Epsilon sensorTOOL's CSV
// export), kKeyenceLk (a Keyence LK controller's fixed-width values, or LK-Navigator's CSV export
// around them) or kColumns (any delimited file, read through options.columns); docs/inputs.md
// shows each layout. Separators `;`, tab or `,`; a decimal comma where the separator is not `,`;
// a UTF-8 byte-order mark, CRLF line ends and a trailing separator are read as written. Invalid
// markers (an empty cell; LK's +FFFFFFF, -FFFFFFF, XXXXXXXX, -------; nan) become NaN, counted by
// kind in scan.read.invalid_markers. Everything else that is wrong throws Error{kBadInput} naming
// the file, the line and the column: a missing column, a unit that does not parse, a cell that is
// neither a number nor a known marker, a time that goes backwards.
[[nodiscard]] Scan ReadSensorScan(const std::filesystem::path& path, ScanFormat format,
                                  const ReadOptions& options = {});
// The same from text already in memory; `name` stands for the file in messages.
[[nodiscard]] Scan ParseSensorScan(std::string text, const std::string& name, ScanFormat format,
                                   const ReadOptions& options = {});

// Every problem of a `--columns` text, in the form of Problems() ("--columns = 'z' violates
// QUANTITY=NAME[:UNIT]"); empty when it is valid.
[[nodiscard]] std::vector<std::string> ColumnsOptionProblems(std::string_view columns);

// formats.md 2.1 from an open file (e.g. an in-memory image, hdf5::File::OpenImage).
[[nodiscard]] Scan ReadHdf5Scan(const hdf5::File& file, const ReadOptions& options = {});

}  // namespace arcwheel::acquisition
