#pragma once
// `arcwheel batch`: many scans, each processed by a child `arcwheel process` into OUTDIR/<scan
// name>, resumable, with an index of the headline numbers (docs/batch.md). A child process per
// scan, so that a bad file or a crash costs only its own row.

#include <cstddef>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

namespace arcwheel::workflows {

struct BatchOptions {
  // Scan files, folders (their *.h5, *.hdf5, *.csv, *.txt), globs and @LIST files.
  std::vector<std::string> inputs;
  std::string outdir;
  int jobs = 1;  // scans processed at once, >= 1
  // Not empty: write an sbatch array script (one task per scan) here instead of running.
  std::string emit_slurm;
  std::vector<std::string> sbatch_lines;  // extra #SBATCH lines of that script
  bool index_only = false;                // run nothing: index what OUTDIR holds
  bool no_index = false;                  // write no index (each Slurm array task)
  // The results store each scan's `arcwheel process` records into (`--db`); empty: ARCWHEEL_DB,
  // else none. Opened before any scan runs, so that an unreachable store fails the batch at once.
  std::string db;
  // Passed unchanged to every `arcwheel process`; must not set the output folder.
  std::vector<std::string> process_options;
  // The `arcwheel` binary each scan runs as `arcwheel process`; empty: this process's own.
  std::filesystem::path arcwheel_binary;
  // Checks process_options once, before any scan runs, against `some_scan` (the first one);
  // throws Error{kInvalidOption}. The command line hands its own parser of `process`.
  std::function<void(const std::vector<std::string>& options, const std::filesystem::path& some_scan)>
      check_process_options;
};

// What a batch came to. Every scan has one status.
struct BatchReport {
  std::size_t scans = 0;
  std::size_t done = 0, reused = 0, failed = 0, interrupted = 0, not_run = 0;
  std::filesystem::path index_csv;     // empty with no_index or emit_slurm
  std::filesystem::path slurm_script;  // set with emit_slurm
  [[nodiscard]] std::size_t Unfinished() const { return failed + interrupted + not_run; }
};

// Plans the scans, checks the options, then runs (or, with index_only, reads) every scan and
// writes OUTDIR/index.csv and index.json; with emit_slurm writes the script and runs nothing.
// A scan's failure is recorded in its row, not thrown. Throws Error{kInvalidOption} for bad
// inputs or options (before any scan runs), Error{kIo} when OUTDIR cannot be written or the store
// cannot be reached (before any scan runs). A reused scan is recorded unless the store holds it. Progress
// goes to stderr: a refreshed bar on a terminal, a line per scan otherwise.
[[nodiscard]] BatchReport RunBatch(const BatchOptions& options);

}  // namespace arcwheel::workflows
