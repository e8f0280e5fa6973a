// The child-process guard of HDF5 readers: what it reports for a read that dies or hangs, and
// that a read which finishes, or refuses the file, is left to the caller.

#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <cstddef>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <optional>
#include <span>
#include <string>
#include <thread>
#include <vector>

#include "core/error.h"
#include "core/hdf5.h"

namespace arcwheel::hdf5 {
namespace {

const std::filesystem::path kPath = "scan.h5";

std::string MessageOf(const std::function<void()>& read, double timeout_s = 0.0) {
  try {
    ReadFirstInChildProcess(kPath, read, timeout_s);
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::kBadInput);
    return e.what();
  }
  return "";
}

TEST(ReadFirstInChildProcess, RefusesAFileWhoseReadKillsTheChild) {
  const std::string message = MessageOf([] { std::abort(); });
  EXPECT_NE(message.find("'scan.h5': reading it crashed libhdf5 (signal 6"), std::string::npos) << message;
}

TEST(ReadFirstInChildProcess, ReportsTheExitStatusOfAChildThatEndsItself) {
  const std::string message = MessageOf([] { std::_Exit(7); });
  EXPECT_NE(message.find("'scan.h5': reading it crashed libhdf5 (exit status 7)"), std::string::npos)
      << message;
}

TEST(ReadFirstInChildProcess, RefusesAReadThatDoesNotFinishInTime) {
  const auto start = std::chrono::steady_clock::now();
  const std::string message = MessageOf([] { std::this_thread::sleep_for(std::chrono::seconds(30)); }, 0.3);
  const std::chrono::duration<double> waited = std::chrono::steady_clock::now() - start;
  EXPECT_NE(message.find("'scan.h5': libhdf5 had not finished reading it after 0.3 s"), std::string::npos)
      << message;
  EXPECT_LT(waited.count(), 10.0) << "the child is killed at the timeout, not waited for";
}

TEST(ReadFirstInChildProcess, StillWaitsForAChildThatClosedItsFilesAndHangs) {
  // The parent learns of the child's exit by a pipe closing; a damaged read that closes the
  // child's files must not pass for an exit: the child is still killed at the timeout.
  const std::string message = MessageOf(
      [] {
        for (int fd = 3; fd < 1024; ++fd) close(fd);
        std::this_thread::sleep_for(std::chrono::seconds(30));
      },
      0.3);
  EXPECT_NE(message.find("'scan.h5': libhdf5 had not finished reading it after 0.3 s"), std::string::npos)
      << message;
}

TEST(ReadFirstInChildProcess, LeavesAFinishedOrRefusedReadToTheCaller) {
  EXPECT_EQ(MessageOf([] {}), "");
  EXPECT_EQ(MessageOf([] { throw Error(ErrorCode::kBadInput, "test", "a refusal of the reader's own"); }),
            "");
}

TEST(ReadFirstInChildProcess, ReadsDirectlyWhenCalledInsideTheChild) {
  // The reader calls the guard again from inside the child: that call must not run its read.
  EXPECT_EQ(MessageOf([] { ReadFirstInChildProcess(kPath, [] { std::abort(); }); }), "");
}

// ---- The read-once variant: the child's arrays handed to the parent. ----

TEST(ReadInChildProcess, HandsTheChildsArraysToTheParentExactly) {
  // 3e6 floats (12 MB) cross the 8 MB copy chunk; the doubles are the closed form i / 7.
  constexpr std::size_t kFloats = 3'000'000;
  constexpr std::size_t kDoubles = 1001;
  SharedArrays arrays;
  const bool handed = ReadInChildProcess(kPath, arrays, [](SharedArrays& shared) {
    const std::span<float> floats = shared.Allocate<float>("z", kFloats);
    for (std::size_t i = 0; i < kFloats; ++i) floats[i] = static_cast<float>(i) * 0.25f;
    const std::span<double> doubles = shared.Allocate<double>("t", kDoubles);
    for (std::size_t i = 0; i < kDoubles; ++i) doubles[i] = static_cast<double>(i) / 7.0;
    (void)shared.Allocate<double>("empty", 0);
  });
  ASSERT_TRUE(handed);
  const std::optional<std::vector<float>> floats = arrays.Take<float>("z");
  ASSERT_TRUE(floats.has_value());
  ASSERT_EQ(floats->size(), kFloats);
  for (std::size_t i = 0; i < kFloats; i += 999) ASSERT_EQ((*floats)[i], static_cast<float>(i) * 0.25f) << i;
  EXPECT_EQ(floats->back(), static_cast<float>(kFloats - 1) * 0.25f);
  const std::optional<std::vector<double>> doubles = arrays.Take<double>("t");
  ASSERT_TRUE(doubles.has_value());
  ASSERT_EQ(doubles->size(), kDoubles);
  for (std::size_t i = 0; i < kDoubles; ++i) ASSERT_EQ((*doubles)[i], static_cast<double>(i) / 7.0) << i;
  EXPECT_EQ(arrays.Take<double>("empty").value().size(), 0u);
  EXPECT_FALSE(arrays.Take<double>("z").has_value()) << "z was stored as float, not double";
  EXPECT_FALSE(arrays.Take<float>("absent").has_value());
}

TEST(ReadInChildProcess, MapsTheChildsArrayIntoTheParentWritableAndAlive) {
  // 3e6 floats (12 MB, many pages): the child's values, i / 4, exactly; the mapping outlives the
  // arrays' memory file and takes writes.
  constexpr std::size_t kFloats = 3'000'000;
  std::optional<SharedArrays::Mapped<float>> floats;
  {
    SharedArrays arrays;
    ASSERT_TRUE(ReadInChildProcess(kPath, arrays, [](SharedArrays& shared) {
      const std::span<float> values = shared.Allocate<float>("z", kFloats);
      for (std::size_t i = 0; i < kFloats; ++i) values[i] = static_cast<float>(i) * 0.25f;
    }));
    floats = arrays.Map<float>("z");
    EXPECT_FALSE(arrays.Map<double>("z").has_value()) << "z was stored as float, not double";
    EXPECT_FALSE(arrays.Map<float>("absent").has_value());
  }
  ASSERT_TRUE(floats.has_value());
  ASSERT_EQ(floats->values.size(), kFloats);
  for (std::size_t i = 0; i < kFloats; i += 999)
    ASSERT_EQ(floats->values[i], static_cast<float>(i) * 0.25f) << i;
  EXPECT_EQ(floats->values.back(), static_cast<float>(kFloats - 1) * 0.25f);
  floats->values[7] = -1.0f;
  EXPECT_EQ(floats->values[7], -1.0f);
}

// A file of `count` floats i / 2 after a 100-byte header (not on a page boundary).
std::filesystem::path WriteFloatsAfterAHeader(const std::filesystem::path& path, std::size_t count) {
  std::ofstream out(path, std::ios::binary);
  const std::string header(100, 'h');
  out.write(header.data(), static_cast<std::streamsize>(header.size()));
  for (std::size_t i = 0; i < count; ++i) {
    const float value = static_cast<float>(i) * 0.5f;
    out.write(reinterpret_cast<const char*>(&value), sizeof value);
  }
  return path;
}

std::string FileBytes(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

TEST(ReadInChildProcess, MapsValuesLeftInTheFileWritableWithoutWritingTheFile) {
  constexpr std::size_t kFloats = 50'000;
  const std::filesystem::path path = WriteFloatsAfterAHeader("left_in_file.bin", kFloats);
  const std::string before = FileBytes(path);
  SharedArrays arrays;
  ASSERT_TRUE(ReadInChildProcess(path, arrays, [](SharedArrays& shared) {
    shared.LeaveInFile<float>("z", {.offset = 100, .count = kFloats});
  }));
  std::optional<SharedArrays::Mapped<float>> floats = arrays.Map<float>("z");
  ASSERT_TRUE(floats.has_value());
  ASSERT_EQ(floats->values.size(), kFloats);
  for (std::size_t i = 0; i < kFloats; ++i) ASSERT_EQ(floats->values[i], static_cast<float>(i) * 0.5f) << i;
  floats->values[3] = -1.0f;
  EXPECT_EQ(floats->values[3], -1.0f);
  EXPECT_EQ(FileBytes(path), before) << "a write into the mapping reached the file";
  const std::optional<std::vector<float>> taken = arrays.Take<float>("z");
  ASSERT_TRUE(taken.has_value());
  EXPECT_EQ(taken->at(3), 1.5f);
  EXPECT_EQ(taken->back(), static_cast<float>(kFloats - 1) * 0.5f);
  std::filesystem::remove(path);
}

TEST(ReadInChildProcess, RefusesAFileThatChangedAfterTheChildReadIt) {
  const std::filesystem::path path = WriteFloatsAfterAHeader("changed_after_read.bin", 1000);
  SharedArrays arrays;
  ASSERT_TRUE(ReadInChildProcess(path, arrays, [](SharedArrays& shared) {
    shared.LeaveInFile<float>("z", {.offset = 100, .count = 1000});
  }));
  std::ofstream(path, std::ios::app) << "appended";
  try {
    (void)arrays.Map<float>("z");
    ADD_FAILURE() << "a file that changed was mapped";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::kBadInput);
    EXPECT_NE(std::string(e.what()).find("changed_after_read.bin' was replaced or changed"),
              std::string::npos)
        << e.what();
  }
  std::filesystem::remove(path);
}

TEST(ReadInChildProcess, LeavesARefusedReadToTheCaller) {
  SharedArrays arrays;
  EXPECT_FALSE(ReadInChildProcess(kPath, arrays, [](SharedArrays& shared) {
    (void)shared.Allocate<double>("z", 10);
    throw Error(ErrorCode::kBadInput, "test", "a refusal of the reader's own");
  }));
}

TEST(ReadInChildProcess, RefusesAFileWhoseReadKillsTheChild) {
  SharedArrays arrays;
  try {
    (void)ReadInChildProcess(kPath, arrays, [](SharedArrays&) { std::abort(); });
    FAIL() << "a crashed child must be reported";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::kBadInput);
    EXPECT_NE(std::string(e.what()).find("'scan.h5': reading it crashed libhdf5 (signal 6"),
              std::string::npos)
        << e.what();
  }
}

TEST(ReadInChildProcess, ReadsDirectlyWhenCalledInsideTheChild) {
  // Inside the guard's child a reader's own guard must not fork again: it says "read it yourself".
  SharedArrays outer;
  const bool handed = ReadInChildProcess(kPath, outer, [](SharedArrays& shared) {
    SharedArrays inner;
    const bool nested = ReadInChildProcess(kPath, inner, [](SharedArrays&) { std::abort(); });
    shared.Allocate<double>("nested", 1)[0] = nested ? 1.0 : 0.0;
  });
  ASSERT_TRUE(handed);
  EXPECT_EQ(outer.Take<double>("nested").value().at(0), 0.0);
}

}  // namespace
}  // namespace arcwheel::hdf5
