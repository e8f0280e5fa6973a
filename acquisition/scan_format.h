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

// The contract's layouts (formats.md 2.1, 2.2) and the sensors' own files (formats.md 2.4).
enum class ScanFormat { kHdf5, kCsv, kSensorTool, kKeyenceLk, kColumns };

struct ScanFormatInfo {
  ScanFormat format;
  // summary.json's input.format and the name by which a format is forced (`--format NAME`).
  std::string_view name;
  // Lower case, with the dot; the first is the one messages suggest. Formats that share an
  // extension are told apart by `sniff`.
  std::span<const std::string_view> extensions;
  // True when the first bytes of a file (a UTF-8 byte-order mark removed) look like this format;
  // null for a format that is only ever chosen by name or by its extension alone.
  bool (*sniff)(std::string_view head) = nullptr;
  // What the sniff looks for, for the message of a file that no sniff claims.
  std::string_view sniff_text;
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

// The format named `name` (`--format`); Error{kInvalidOption, stage} naming every format otherwise.
[[nodiscard]] ScanFormat ScanFormatNamed(std::string_view name, std::string_view stage);

// A Keyence LK controller's fixed-width value: a sign and 7 characters (`+01.2345`, `-FFFFFFF`),
// `XXXXXXXX` (alarm) or `-------` (waiting).
[[nodiscard]] bool IsKeyenceLkValue(std::string_view cell);

// The first format, in table order, whose sniff claims `head` (the file's first bytes); empty when
// none does.
[[nodiscard]] std::optional<ScanFormat> SniffScanFormat(std::string_view head);

// The reader for a file: the one named by `forced` when not empty; `columns` when a column map is
// given; else by the extension, and among the formats that share it (.csv, .txt) by a sniff of the
// file's first 4 KiB. Error{kBadInput, stage} for an extension no format claims, or a header no
// sniff claims (naming every format tried and what it looks for, and `--format NAME` and
// `--columns` that force one); Error{kIo} when the file cannot be read.
[[nodiscard]] ScanFormat ScanFormatOfContent(const std::filesystem::path& path, std::string_view forced,
                                             bool has_column_map, std::string_view stage);

}  // namespace arcwheel::acquisition
