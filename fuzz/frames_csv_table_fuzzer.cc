// libFuzzer target: the CSV table reader of the frames inputs (point pairs, record lists), and its
// number parser on every cell. Any input must give a table or throw arcwheel::Error.

#include <cstddef>
#include <cstdint>

#include "core/error.h"
#include "frames/csv_table.h"
#include "fuzz/fuzz_input.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  try {
    const auto table =
        arcwheel::frames::ReadCsvTable(arcwheel::fuzz::WriteInput(data, size, "pairs.csv"), "fuzz");
    for (size_t row = 0; row < table.cells.size(); ++row) {
      if (table.cells[row].size() != table.columns.size()) __builtin_trap();
      for (size_t column = 0; column < table.columns.size(); ++column) {
        try {
          (void)table.Number(row, column, "fuzz");
        } catch (const arcwheel::Error&) {
        }
      }
    }
  } catch (const arcwheel::Error&) {
  }
  return 0;
}
