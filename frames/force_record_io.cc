#include "frames/force_record_io.h"

#include <fmt/core.h>

#include <array>
#include <charconv>
#include <map>
#include <tuple>
#include <vector>

#include "core/error.h"
#include "core/hdf5.h"
#include "frames/csv_table.h"

namespace arcwheel::frames {
namespace {

constexpr const char* kForceRecordIoStage = "frames.force_record";

enum class Kind { kTime, kForce, kMoment };

struct Channel {
  const char* base;
  Kind kind;
  std::vector<double> ForceRecord::*values;
};
constexpr std::array<Channel, 7> kChannels = {{
    {"t", Kind::kTime, &ForceRecord::t_s},
    {"Fx", Kind::kForce, &ForceRecord::fx_N},
    {"Fy", Kind::kForce, &ForceRecord::fy_N},
    {"Fz", Kind::kForce, &ForceRecord::fz_N},
    {"Mx", Kind::kMoment, &ForceRecord::mx_Nmm},
    {"My", Kind::kMoment, &ForceRecord::my_Nmm},
    {"Mz", Kind::kMoment, &ForceRecord::mz_Nmm},
}};

// Factor to N, N mm or s; nullopt for a unit this kind does not accept.
std::optional<double> UnitFactor(Kind kind, const std::string& unit) {
  static const std::map<std::pair<Kind, std::string>, double> kFactors = {
      {{Kind::kTime, "s"}, 1.0},     {{Kind::kForce, "N"}, 1.0},      {{Kind::kForce, "kN"}, 1000.0},
      {{Kind::kMoment, "Nmm"}, 1.0}, {{Kind::kMoment, "Nm"}, 1000.0},
  };
  const auto found = kFactors.find({kind, unit});
  if (found == kFactors.end()) return std::nullopt;
  return found->second;
}

const char* AcceptedUnits(Kind kind) {
  switch (kind) {
    case Kind::kTime:
      return "s";
    case Kind::kForce:
      return "N or kN";
    case Kind::kMoment:
      return "Nmm or Nm";
  }
  return "";
}

// A channel found in the file: its stored name and the factor to our units.
struct Located {
  std::string name;
  double factor = 1.0;
};

// Finds the one column/dataset of `channel` among `names`, reading its unit from the suffix or,
// for a bare name, from `note_unit` (the file's note or the option).
Located Locate(const Channel& channel, const std::vector<std::string>& names, const std::string& note_unit,
               const std::string& where) {
  std::vector<Located> found;
  for (const std::string& name : names) {
    const std::string base = channel.base;
    std::string unit;
    if (name == base) {
      unit = channel.kind == Kind::kTime && note_unit.empty() ? "s" : note_unit;
      if (unit.empty()) {
        throw Error(
            ErrorCode::kBadInput, kForceRecordIoStage,
            fmt::format("{}: column '{}' has no unit: name it {}_<unit> or give the {} note ({})", where,
                        name, base, channel.kind == Kind::kForce ? "force_unit" : "moment_unit",
                        AcceptedUnits(channel.kind)));
      }
    } else if (name.starts_with(base + "_")) {
      unit = name.substr(base.size() + 1);
    } else {
      continue;
    }
    const auto factor = UnitFactor(channel.kind, unit);
    if (!factor) {
      throw Error(
          ErrorCode::kBadInput, kForceRecordIoStage,
          fmt::format("{}: unit '{}' of '{}' is not {}", where, unit, name, AcceptedUnits(channel.kind)));
    }
    found.push_back({name, *factor});
  }
  if (found.empty()) {
    throw Error(ErrorCode::kBadInput, kForceRecordIoStage,
                fmt::format("{}: no '{}' channel (expected e.g. {}_{})", where, channel.base, channel.base,
                            channel.kind == Kind::kTime    ? "s"
                            : channel.kind == Kind::kForce ? "N"
                                                           : "Nmm"));
  }
  if (found.size() > 1) {
    throw Error(ErrorCode::kBadInput, kForceRecordIoStage,
                fmt::format("{}: channel '{}' appears twice ('{}' and '{}')", where, channel.base,
                            found[0].name, found[1].name));
  }
  return found.front();
}

std::string NoteUnit(Kind kind, const ForceRecordReadOptions& options,
                     const std::map<std::string, std::string>& notes) {
  if (kind == Kind::kTime) return {};
  const std::string& option = kind == Kind::kForce ? options.force_unit : options.moment_unit;
  if (!option.empty()) return option;
  const auto note = notes.find(kind == Kind::kForce ? "force_unit" : "moment_unit");
  return note == notes.end() ? std::string() : note->second;
}

std::optional<double> PlatformHeight(const std::map<std::string, std::string>& notes,
                                     const std::string& where) {
  const auto note = notes.find("platform_height_mm");
  if (note == notes.end()) return std::nullopt;
  double value = 0.0;
  const std::string& text = note->second;
  const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (error != std::errc() || end != text.data() + text.size() || !std::isfinite(value)) {
    throw Error(ErrorCode::kBadInput, kForceRecordIoStage,
                fmt::format("{}: platform_height_mm '{}' is not a number", where, text));
  }
  return value;
}

ForceRecordFile ReadCsv(const std::filesystem::path& path, const ForceRecordReadOptions& options) {
  const CsvTable table = ReadCsvTable(path, kForceRecordIoStage);
  const std::string where = fmt::format("'{}'", path.string());
  ForceRecordFile file;
  file.record.source = path.string();
  for (const Channel& channel : kChannels) {
    const Located located =
        Locate(channel, table.columns, NoteUnit(channel.kind, options, table.notes), where);
    const size_t column = *table.Find(located.name);
    std::vector<double>& values = file.record.*channel.values;
    values.reserve(table.cells.size());
    for (size_t row = 0; row < table.cells.size(); ++row)
      values.push_back(located.factor * table.Number(row, column, kForceRecordIoStage));
  }
  // Name time faults by file line rather than sample index.
  for (size_t row = 1; row < table.cells.size(); ++row) {
    if (!(file.record.t_s[row] > file.record.t_s[row - 1])) {
      throw Error(ErrorCode::kBadInput, kForceRecordIoStage,
                  fmt::format("{} line {}: t_s {} does not increase (previous {})", where,
                              table.line_numbers[row], file.record.t_s[row], file.record.t_s[row - 1]));
    }
  }
  file.platform_height_mm = PlatformHeight(table.notes, where);
  ValidateForceRecord(file.record);
  return file;
}

ForceRecordFile ReadHdf5(const std::filesystem::path& path, const ForceRecordReadOptions& options) {
  hdf5::ReadFirstInChildProcess(path, [&] { (void)ReadHdf5(path, options); });
  const hdf5::File h5 = hdf5::File::OpenReadOnly(path);
  const std::string where = fmt::format("'{}'", path.string());
  std::map<std::string, std::string> notes;
  for (const char* key : {"force_unit", "moment_unit"}) {
    if (const auto text = h5.ReadAttributeString("/", key)) notes[key] = *text;
  }
  if (const auto height = h5.ReadAttributeDouble("/", "platform_height_mm"))
    notes["platform_height_mm"] = fmt::format("{}", *height);
  ForceRecordFile file;
  file.record.source = path.string();
  for (const Channel& channel : kChannels) {
    std::vector<std::string> names;
    const std::string base = channel.base;
    for (const std::string suffix : {"", "_s", "_N", "_kN", "_Nmm", "_Nm"}) {
      if (h5.HasObject("/" + base + suffix)) names.push_back(base + suffix);
    }
    std::string note_unit = NoteUnit(channel.kind, options, notes);
    if (h5.HasObject("/" + base)) {
      if (const auto unit = h5.ReadAttributeString("/" + base, "unit");
          unit && options.force_unit.empty() && options.moment_unit.empty())
        note_unit = *unit;
    }
    const Located located = Locate(channel, names, note_unit, where);
    const std::string dataset = "/" + located.name;
    if (h5.Shape(dataset).size() != 1) {
      throw Error(ErrorCode::kBadInput, kForceRecordIoStage,
                  fmt::format("{}: dataset {} is not one-dimensional", where, dataset));
    }
    std::vector<double> values = h5.ReadDoubles(dataset);
    for (double& v : values) v *= located.factor;
    file.record.*channel.values = std::move(values);
  }
  file.platform_height_mm = PlatformHeight(notes, where);
  ValidateForceRecord(file.record);
  return file;
}

}  // namespace

std::vector<std::string> ForceRecordReadOptions::Problems() const {
  std::vector<std::string> problems;
  for (const auto& [unit, kind, flag] : {std::tuple{&force_unit, Kind::kForce, "--force-unit"},
                                         std::tuple{&moment_unit, Kind::kMoment, "--moment-unit"}}) {
    if (!unit->empty() && !UnitFactor(kind, *unit))
      problems.push_back(fmt::format("{} = '{}' violates {}", flag, *unit, AcceptedUnits(kind)));
  }
  return problems;
}

ForceRecordFile ReadForceRecord(const std::filesystem::path& path, const ForceRecordReadOptions& options) {
  ThrowIfProblems(ErrorCode::kInvalidOption, kForceRecordIoStage, options.Problems());
  const std::string extension = path.extension().string();
  if (extension == ".h5" || extension == ".hdf5") return ReadHdf5(path, options);
  return ReadCsv(path, options);
}

std::string ForceRecordCsv(const ForceRecord& record,
                           const std::vector<std::pair<std::string, std::string>>& notes) {
  std::string text;
  for (const auto& [key, value] : notes) text += fmt::format("# {}: {}\n", key, value);
  text += "t_s,Fx_N,Fy_N,Fz_N,Mx_Nmm,My_Nmm,Mz_Nmm\n";
  for (size_t i = 0; i < record.size(); ++i) {
    text += fmt::format("{},{},{},{},{},{},{}\n", record.t_s[i], record.fx_N[i], record.fy_N[i],
                        record.fz_N[i], record.mx_Nmm[i], record.my_Nmm[i], record.mz_Nmm[i]);
  }
  return text;
}

void WriteForceRecordHdf5(const std::filesystem::path& path, const ForceRecord& record,
                          std::optional<double> platform_height_mm) {
  hdf5::File h5 = hdf5::File::Create(path);
  const std::array<std::pair<const char*, const std::vector<double>*>, 7> datasets = {{
      {"/t_s", &record.t_s},
      {"/Fx_N", &record.fx_N},
      {"/Fy_N", &record.fy_N},
      {"/Fz_N", &record.fz_N},
      {"/Mx_Nmm", &record.mx_Nmm},
      {"/My_Nmm", &record.my_Nmm},
      {"/Mz_Nmm", &record.mz_Nmm},
  }};
  for (const auto& [name, values] : datasets) h5.WriteDoubles(name, *values, {values->size()});
  if (platform_height_mm) h5.WriteAttribute("/", "platform_height_mm", *platform_height_mm);
}

}  // namespace arcwheel::frames
