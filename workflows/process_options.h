#pragma once
// The one table of `arcwheel process`'s options (PDAL-style): each option's flag, help with its
// unit, the summary.json "processing" key it is recorded under, and the field of
// ProcessPipelineOptions it sets, whose initial value is the default. The command line
// (cli/command_process.cc), the Python module (python/src/process.cc, keywords in snake_case) and the
// run record (process_pipeline.cc) are all bound from it, so that they cannot disagree.

#include <functional>
#include <span>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "workflows/process_pipeline.h"

namespace arcwheel::workflows {

// A choice among names (`--despike median`), held by the options as an enum whose values are the
// names' positions.
struct ChoiceRef {
  std::span<const std::string_view> names;
  std::function<std::size_t()> get;
  std::function<void(std::size_t)> set;
};

// The field an option sets, in one ProcessPipelineOptions.
using OptionRef = std::variant<int*, double*, bool*, std::string*, ChoiceRef>;

struct ProcessOption {
  // "--band-half-width-mm"; empty for a parameter that is recorded but has no flag.
  std::string_view flag;
  std::string_view help;
  // summary.json's processing key (schema/summary.h); empty when not recorded.
  std::string_view record_key;
  std::function<OptionRef(ProcessPipelineOptions&)> field;
  // The help shows the default (not for a default that means "chosen from the data").
  bool show_default = true;
  // The value names a file that must exist.
  bool existing_file = false;
};

// Every row, in the order of the record (the numbers, then the texts) and then the rest.
[[nodiscard]] const std::vector<ProcessOption>& ProcessOptionTable();

// The keyword of a flag in Python: "--despike-window" -> "despike_window".
[[nodiscard]] std::string KeywordOf(std::string_view flag);

// A choice's name as the command line spells it.
[[nodiscard]] std::string_view NameOf(const ChoiceRef& choice);

// Sets a choice by name; an unknown name becomes a problem in options.binding_problems in the form
// of Problems(): "--despike = mean violates median, moving-mean or none".
void SetChoice(std::string_view flag, const ChoiceRef& choice, std::string_view name,
               ProcessPipelineOptions& options);

}  // namespace arcwheel::workflows
