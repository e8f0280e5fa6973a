// Every input the fuzzers found (testdata/fuzz_regressions/), run through the command that reads
// it as a user would: a clear refusal naming the file, exit status 3, nothing written. Before
// their fixes these exhausted memory, ran for seconds on a 5 kB file, or escaped as an internal
// error.

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <fstream>
#include <string>

#include "core/testing/testing.h"

namespace arcwheel {
namespace {

using testing::RunArcwheel;
using testing::TempDir;

struct Finding {
  const char* name;
  const char* file;       // in testdata/fuzz_regressions/
  const char* arguments;  // {in}: the file, {dir}: a scratch folder
  const char* message;    // part of the refusal
  // The polishing job takes the finding as its error map: a CSV is read as scattered points,
  // other files by their extension.
  bool scattered_map = true;
};

class FuzzFinding : public ::testing::TestWithParam<Finding> {};

TEST_P(FuzzFinding, IsRefusedClearlyAndWritesNothing) {
  const Finding& finding = GetParam();
  TempDir dir;
  std::ofstream(dir / "points.csv") << "x_mm,y_mm,z_mm\n1,2,3\n";
  std::ofstream(dir / "job.json")
      << R"({"surface": {"vertex_radius_mm": 400}, "aperture": {"diameter_mm": 30},
    "error_map": {"file": ")"
      << (testing::SourceDir() / "testdata" / "fuzz_regressions" / finding.file).string()
      << (finding.scattered_map ? R"(", "layout": "scattered"},)" : R"("},)") << R"(
    "removal_function": {"peak_rate_um_per_s": 1, "fwhm_mm": 8}, "machine": {"max_speed_mm_s": 100}})";
  const std::string input = (testing::SourceDir() / "testdata" / "fuzz_regressions" / finding.file).string();
  const std::string arguments = fmt::format(fmt::runtime(finding.arguments), fmt::arg("in", input),
                                            fmt::arg("dir", dir.path().string()));
  const auto run = RunArcwheel(arguments);
  EXPECT_EQ(run.exit_status, 3) << run.output;
  EXPECT_NE(run.output.find(finding.file), std::string::npos) << "the message names the file: " << run.output;
  EXPECT_NE(run.output.find(finding.message), std::string::npos) << run.output;
  EXPECT_EQ(testing::ListFolder(dir.path()), "job.json\npoints.csv\n");
}

INSTANTIATE_TEST_SUITE_P(
    Found, FuzzFinding,
    ::testing::Values(
        // scan_hdf5_fuzzer: a header declaring 2e14 values (read from memory; acquisition/readers_test.cc
        // checks that path). From the file, the library cannot even open the damaged /scan group
        // to list its attributes.
        Finding{"ScanDatasetLargerThanItsFile", "scan_hdf5_huge_dataset.h5", "process {in} -o {dir}/out",
                "bad input: hdf5: cannot list the attributes of"},
        // force_record_hdf5_fuzzer: a float type of 688 MB per value.
        Finding{"ForceRecordNumberOfAbsurdSize", "force_record_huge_number_type.h5",
                "headcenter solve {in} --z0-mm 20 -o {dir}/centre.json", "has numbers of 687865864 bytes"},
        // force_record_hdf5_fuzzer: a damaged object header made libhdf5 ask for 4 GB while opening
        // the file; whether that allocation succeeds or not, the file is refused.
        Finding{"ForceRecordDamagedObjectHeader", "force_record_damaged_object_header.h5",
                "headcenter solve {in} --z0-mm 20 -o {dir}/centre.json", "bad input"},
        // polishing_scattered_fuzzer: one stray point 8 km away made a grid of 6e7 empty nodes.
        Finding{"ScatteredMapWithAStrayPoint", "polishing_scattered_stray_point.csv",
                "polish {dir}/job.json -o {dir}/out", "a stray point?"},
        // transform_json_fuzzer: a number that overflows a double escaped the JSON readers.
        Finding{"JsonNumberOverflow", "transform_number_overflow.json",
                "transform apply {in} {dir}/points.csv -o {dir}/out.csv", "number overflow"},
        // zygo_datx_fuzzer: a global heap object of size 0 under a converter attribute made
        // libhdf5 1.10.8 loop for ever while reading it; the heap is now checked first.
        Finding{"DatxGlobalHeapThatHangsTheLibrary", "zygo_datx_heap_hang.datx",
                "polish {dir}/job.json -o {dir}/out", "global heap at byte 6528 is damaged", false},
        // zygo_datx_fuzzer: a reference to a heap object the collection does not hold made
        // libhdf5 1.10.8 read through a null pointer; references are now checked first.
        Finding{"DatxReferenceToAMissingHeapObject", "zygo_datx_missing_heap_object.datx",
                "polish {dir}/job.json -o {dir}/out",
                "refers to object 8388616 of the global heap at byte 6528", false},
        // zygo_datx_fuzzer: converter types whose members lie past the end of the compound made
        // libhdf5 1.10.8 copy from outside its buffer while converting them; the layout of a
        // compound is now checked before it is read.
        Finding{"DatxConverterMemberPastItsCompound", "zygo_datx_damaged_converter_type.datx",
                "polish {dir}/job.json -o {dir}/out",
                "has a member of 8 bytes at byte 8 of a compound of 9 bytes", false},
        Finding{"DatxConverterMemberFarPastItsCompound", "zygo_datx_member_past_compound.datx",
                "polish {dir}/job.json -o {dir}/out",
                "has a member of 16 bytes at byte 9371664 of a compound of 32 bytes", false},
        // zygo_datx_fuzzer: a group heap declaring 30 GB; where that allocation fails, libhdf5
        // 1.10.8 copies into the null pointer it got back. Read first in a child process, the file
        // is refused when the child dies (core/hdf5_child_test.cc checks that message); where the
        // allocation succeeds, the library's own read fails. Either way: refused, nothing written.
        Finding{"DatxThatCrashesTheLibrary", "zygo_datx_local_heap_crashes_libhdf5.datx",
                "polish {dir}/job.json -o {dir}/out", "bad input", false}),
    [](const ::testing::TestParamInfo<Finding>& test) { return std::string(test.param.name); });

// Report inputs are read from an output folder: the finding stands in for one file of it, the
// others are the fuzzers' seeds (valid files of their kind).
struct FolderFinding {
  const char* name;
  const char* file;      // in testdata/fuzz_regressions/
  const char* as;        // its name in the output folder
  const char* seeds[2];  // fuzz/seeds/<target>/<file> copied beside it
  const char* message;
};

class FuzzFindingInAFolder : public ::testing::TestWithParam<FolderFinding> {};

TEST_P(FuzzFindingInAFolder, IsRefusedClearlyAndWritesNothing) {
  const FolderFinding& finding = GetParam();
  TempDir dir;
  const auto source = testing::SourceDir();
  std::filesystem::copy_file(source / "testdata" / "fuzz_regressions" / finding.file, dir / finding.as);
  for (const char* seed : finding.seeds) {
    if (seed == nullptr) continue;
    const std::filesystem::path path = source / "fuzz" / "seeds" / seed;
    std::filesystem::copy_file(path, dir / path.filename());
  }
  const std::string before = testing::ListFolder(dir.path());
  const auto run = RunArcwheel("report " + dir.path().string());
  EXPECT_EQ(run.exit_status, 3) << run.output;
  EXPECT_NE(run.output.find(finding.as), std::string::npos) << "the message names the file: " << run.output;
  EXPECT_NE(run.output.find(finding.message), std::string::npos) << run.output;
  EXPECT_EQ(testing::ListFolder(dir.path()), before);
}

INSTANTIATE_TEST_SUITE_P(
    Found, FuzzFindingInAFolder,
    ::testing::Values(
        // report_wheel_map_fuzzer: a number type of absurd size made HDF5 ask for 2 GB.
        FolderFinding{"WheelMapNumberOfAbsurdSize",
                      "report_wheel_map_huge_number_type.h5",
                      "wheel_map.h5",
                      {"report_summary_fuzzer/summary.json", nullptr},
                      "(damaged?)"},
        // polish_residual_map_fuzzer: a few nodes spanning a grid of millions took seconds to place.
        FolderFinding{"ResidualMapOfFewNodesOnAVastGrid",
                      "polish_residual_map_sparse_grid.csv",
                      "residual_map.csv",
                      {"polish_summary_fuzzer/polish_summary.json", "polish_path_fuzzer/polishing_path.csv"},
                      "not the nodes of one regular grid"}),
    [](const ::testing::TestParamInfo<FolderFinding>& test) { return std::string(test.param.name); });

}  // namespace
}  // namespace arcwheel
