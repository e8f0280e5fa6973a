#include "schema/version.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "core/error.h"

namespace arcwheel::schema {
namespace {

using ::testing::AllOf;
using ::testing::HasSubstr;

constexpr Version kReads{1, 3};

std::string RefusalOf(const std::string& found) {
  try {
    CheckVersion(found, kReads, "out/summary.json", "key 'schema_version'", "test.stage");
  } catch (const Error& error) {
    EXPECT_EQ(error.code(), ErrorCode::kBadInput);
    return error.what();
  }
  ADD_FAILURE() << "'" << found << "' was accepted";
  return "";
}

TEST(VersionText, IsMajorDotMinor) {
  EXPECT_EQ(VersionText({1, 0}), "1.0");
  EXPECT_EQ(VersionText({12, 34}), "12.34");
}

TEST(CheckVersion, AcceptsAFileThatRecordsNoVersion) {
  EXPECT_NO_THROW(CheckVersion(std::nullopt, kReads, "f", "key 'schema_version'", "s"));
}

TEST(CheckVersion, AcceptsEveryMinorVersionOfTheSameMajor) {
  for (const char* found : {"1.0", "1.3", "1.9", "1.10"}) {
    EXPECT_NO_THROW(CheckVersion(std::string(found), kReads, "f", "key 'schema_version'", "s")) << found;
  }
}

TEST(CheckVersion, RefusesANewerMajorNamingFileFoundAndSupported) {
  EXPECT_THAT(RefusalOf("2.0"),
              AllOf(HasSubstr("test.stage"), HasSubstr("'out/summary.json'"),
                    HasSubstr("key 'schema_version' = '2.0'"), HasSubstr("1.x"), HasSubstr("1.3")));
}

TEST(CheckVersion, RefusesAnOlderMajorThatNeverExisted) { EXPECT_THAT(RefusalOf("0.9"), HasSubstr("'0.9'")); }

TEST(CheckVersion, RefusesTextThatIsNotMajorDotMinor) {
  for (const char* found : {"", "1", "1.", ".1", "1.0.0", "one.zero", "-1.0", "1.-1", " 1.0", "1.0 "}) {
    EXPECT_THAT(RefusalOf(found), HasSubstr("is not a schema version MAJOR.MINOR")) << "'" << found << "'";
  }
}

}  // namespace
}  // namespace arcwheel::schema
