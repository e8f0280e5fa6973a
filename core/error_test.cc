#include "core/error.h"

#include <gtest/gtest.h>

#include <string>
#include <vector>

namespace arcwheel {
namespace {

TEST(ThrowIfProblems, ThrowsNothingWithoutProblems) {
  EXPECT_NO_THROW(ThrowIfProblems(ErrorCode::kInvalidOption, "test.stage", {}));
}

TEST(ThrowIfProblems, ThrowsOneErrorListingEveryProblemInOrderWithTheCodeAndStage) {
  try {
    ThrowIfProblems(ErrorCode::kInvalidOption, "test.stage",
                    {"--a = -1 violates > 0", "b = 7 violates <= 5", "c = nan violates finite"});
    ADD_FAILURE() << "no problems reported";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::kInvalidOption);
    EXPECT_EQ(e.stage(), "test.stage");
    EXPECT_EQ(std::string(e.what()),
              "test.stage: --a = -1 violates > 0; b = 7 violates <= 5; c = nan violates finite");
  }
}

TEST(ThrowIfProblems, KeepsTheCodeItIsGiven) {
  try {
    ThrowIfProblems(ErrorCode::kBadInput, "test.stage", {"x = 0 violates > 0"});
    ADD_FAILURE() << "no problems reported";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::kBadInput);
    EXPECT_EQ(std::string(e.what()), "test.stage: x = 0 violates > 0");
  }
}

TEST(Error, KeepsItsStageApartFromTheMessage) {
  const Error error(ErrorCode::kBadInput, "acquisition.validate", "'C: scans/w1.h5': spindle_rpm missing");
  EXPECT_EQ(error.stage(), "acquisition.validate");
  EXPECT_EQ(std::string(error.what()), "acquisition.validate: 'C: scans/w1.h5': spindle_rpm missing");
}

TEST(JoinProblems, JoinsWithASemicolonAndLeavesOneProblemAlone) {
  EXPECT_EQ(JoinProblems({}), "");
  EXPECT_EQ(JoinProblems({"a"}), "a");
  EXPECT_EQ(JoinProblems({"a", "b"}), "a; b");
}

}  // namespace
}  // namespace arcwheel
