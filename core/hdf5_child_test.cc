// The child-process guard of HDF5 readers: what it reports for a read that dies or hangs, and
// that a read which finishes, or refuses the file, is left to the caller.

#include <gtest/gtest.h>

#include <chrono>
#include <cstdlib>
#include <string>
#include <thread>

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

TEST(ReadFirstInChildProcess, LeavesAFinishedOrRefusedReadToTheCaller) {
  EXPECT_EQ(MessageOf([] {}), "");
  EXPECT_EQ(MessageOf([] { throw Error(ErrorCode::kBadInput, "test", "a refusal of the reader's own"); }),
            "");
}

TEST(ReadFirstInChildProcess, ReadsDirectlyWhenCalledInsideTheChild) {
  // The reader calls the guard again from inside the child: that call must not run its read.
  EXPECT_EQ(MessageOf([] { ReadFirstInChildProcess(kPath, [] { std::abort(); }); }), "");
}

}  // namespace
}  // namespace arcwheel::hdf5
