#pragma once
// Readers and writers of six-axis force/torque records (layout in docs/frames.md):
//
// CSV: `# key: value` note lines, then a header naming the channels, one sample per row:
//   t_s,Fx_N,Fy_N,Fz_N,Mx_Nmm,My_Nmm,Mz_Nmm
// HDF5: one 1-D dataset per channel at the file root, with the same names.
// A channel's unit is its name's suffix: forces _N or _kN, moments _Nmm or _Nm. A bare name
// (Fx, Mx) takes its unit from the note `force_unit` / `moment_unit` (CSV `# force_unit: N`, HDF5 a
// root or dataset string attribute `unit`) or from ForceRecordReadOptions. Everything is converted
// to N and N mm. Other columns are ignored. The note `platform_height_mm` is returned if present.

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "frames/force_centre.h"

namespace arcwheel::frames {

struct ForceRecordReadOptions {
  std::string force_unit;   // "N" or "kN"; empty: from the file
  std::string moment_unit;  // "Nmm" or "Nm"; empty: from the file
  // Empty when valid, else one line per violation with its value, named by the flag of `arcwheel
  // headcenter`: "--force-unit = 'lbf' violates N or kN".
  [[nodiscard]] std::vector<std::string> Problems() const;
};

struct ForceRecordFile {
  ForceRecord record;
  std::optional<double> platform_height_mm;  // from the file's notes
};

// By extension: .h5/.hdf5 HDF5, anything else CSV. Throws Error{kIo} if unreadable and
// Error{kBadInput, "frames.force_record"} naming the file and the line, channel or sample for
// a missing or ambiguous channel, an unknown or conflicting unit, mismatched lengths or
// cell counts, a non-finite value or a non-increasing time.
[[nodiscard]] ForceRecordFile ReadForceRecord(const std::filesystem::path& path,
                                              const ForceRecordReadOptions& options = {});

// Full-precision CSV (shortest round-trip numbers) in N and N mm, with `notes` as `# key: value`.
[[nodiscard]] std::string ForceRecordCsv(const ForceRecord& record,
                                         const std::vector<std::pair<std::string, std::string>>& notes = {});
// Writes the HDF5 layout to `path` (the caller makes it atomic). Throws Error{kIo}.
void WriteForceRecordHdf5(const std::filesystem::path& path, const ForceRecord& record,
                          std::optional<double> platform_height_mm = std::nullopt);

}  // namespace arcwheel::frames
