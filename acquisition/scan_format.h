#pragma once
// The one table of raw scan formats (formats.md section 2): each format's id, its name and the
// file extensions that select it. The readers (ReadScan), the writers (WriteScan), `batch`'s choice
// of files in a folder and the run record's `input.format` all ask this table, so that they agree.
// Formats told apart by their content rather than their extension (sensor software's CSV exports
// share `.csv`) are meant to join it as further entries, chosen by a sniff of the file's first bytes
// after the extension has narrowed the candidates, or forced by name.

#include <filesystem>
#include <optional>
#include <span>
#include <string>
#include <string_view>

namespace arcwheel::acquisition {

enum class ScanFormat { kHdf5, kCsv };

struct ScanFormatInfo {
  ScanFormat format;
  // summary.json's input.format and the name by which a format is forced.
  std::string_view name;
  // Lower case, with the dot; the first is the one messages suggest.
  std::span<const std::string_view> extensions;
};

// Every format, in the order messages list them.
[[nodiscard]] std::span<const ScanFormatInfo> ScanFormats();
[[nodiscard]] const ScanFormatInfo& InfoOf(ScanFormat format);

// The format the file name's extension selects, compared case-insensitively (`SCAN.H5` is HDF5);
// empty when no format claims it.
[[nodiscard]] std::optional<ScanFormat> ScanFormatOfName(const std::filesystem::path& path);

// The same, or Error{kBadInput, stage} "'PATH': unknown scan file type '.x' (expected .h5, .hdf5,
// .csv or .txt)" for a file name no format claims.
[[nodiscard]] ScanFormat ScanFormatOfFile(const std::filesystem::path& path, std::string_view stage);

// Every extension of every format for messages: ".h5, .hdf5, .csv or .txt".
[[nodiscard]] std::string ScanExtensionsText();

}  // namespace arcwheel::acquisition
