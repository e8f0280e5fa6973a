#include "core/json_job.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <string>

#include "core/error.h"

namespace arcwheel {
namespace {

using nlohmann::json;
using ::testing::HasSubstr;

const JsonJobContext kContext{.file = "job.json", .stage = "test.job", .docs_page = "docs/test.md"};

// The message of the Error that `read` throws on the root section of `text`.
template <class Read>
std::string MessageOf(const std::string& text, Read read) {
  const json document = json::parse(text);
  JsonSection root(document, kContext);
  try {
    read(root);
    root.Finish();
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::kBadInput) << e.what();
    return e.what();
  }
  return "accepted";
}

TEST(JsonSection, ReadsEachTypeAndRecordsTheDefaultsItFilledIn) {
  const json document = json::parse(R"({"a": 2.5, "n": 3, "flag": true, "s": {"k": [1, 2]}})");
  JsonSection root(document, kContext);
  EXPECT_EQ(root.Number("a", 0.0), 2.5);
  EXPECT_EQ(root.Number("b", 7.0), 7.0);
  EXPECT_EQ(root.Integer("n", 0), 3);
  EXPECT_EQ(root.WholeNumber("w", 4, 1, 9), 4);
  EXPECT_TRUE(root.Boolean("flag", false));
  EXPECT_EQ(root.Choice("side", {"left", "right"}), "left");
  EXPECT_FALSE(root.OptionalNumber("absent").has_value());
  std::vector<double> k;
  root.Section("s", true, [&k](JsonSection& s) { k = s.RequiredNumbers("k", 2); });
  root.Finish();
  EXPECT_EQ(k, (std::vector<double>{1.0, 2.0}));
  const json expected = json::parse(
      R"({"a": 2.5, "b": 7.0, "n": 3, "w": 4, "flag": true, "side": "left", "s": {"k": [1.0, 2.0]}})");
  EXPECT_EQ(root.resolved(), expected);
}

TEST(JsonSection, NamesTheFileTheDottedKeyWhatWasExpectedAndTheValueAsWritten) {
  EXPECT_THAT(
      MessageOf(R"({"s": {"x": "3"}})",
                [](JsonSection& r) { r.Section("s", true, [](JsonSection& s) { s.Number("x", 0); }); }),
      HasSubstr("test.job: 'job.json': key 's.x' expected a finite number, got \"3\""));
  EXPECT_THAT(MessageOf(R"({"p": 2.5})", [](JsonSection& r) { r.WholeNumber("p", 0, 0, 20); }),
              HasSubstr("key 'p' expected a whole number within 0 .. 20, got 2.5"));
  EXPECT_THAT(MessageOf(R"({"p": 21})", [](JsonSection& r) { r.WholeNumber("p", 0, 0, 20); }),
              HasSubstr("key 'p' expected a whole number within 0 .. 20, got 21"));
  EXPECT_THAT(MessageOf(R"({"n": 30000000000})", [](JsonSection& r) { r.Integer("n", 0); }),
              HasSubstr("key 'n' expected an integer, got 30000000000"));
  EXPECT_THAT(MessageOf(R"({"n": 2.0})", [](JsonSection& r) { r.Integer("n", 0); }),
              HasSubstr("key 'n' expected an integer, got 2.0"));
  EXPECT_THAT(MessageOf(R"({"b": 1})", [](JsonSection& r) { r.Boolean("b", false); }),
              HasSubstr("key 'b' expected true or false, got 1"));
  EXPECT_THAT(MessageOf(R"({"c": "up"})",
                        [](JsonSection& r) {
                          r.Choice("c", {"left", "right"});
                        }),
              HasSubstr("key 'c' expected one of \"left\", \"right\", got \"up\""));
  EXPECT_THAT(MessageOf(R"({"v": [1, 2, 3]})",
                        [](JsonSection& r) {
                          r.Numbers("v", {0.0, 0.0});
                        }),
              HasSubstr("key 'v' expected an array of 2 finite numbers, got [1,2,3]"));
  EXPECT_THAT(MessageOf(R"({})", [](JsonSection& r) { r.RequiredNumber("m"); }),
              HasSubstr("key 'm' expected a finite number, got nothing"));
  EXPECT_THAT(
      MessageOf(R"({"t": [{"x": 1}, 5]})",
                [](JsonSection& r) { r.Elements("t", "objects", [](JsonSection& e) { e.Number("x", 0); }); }),
      HasSubstr("key 't[1]' expected an object, got 5"));
}

TEST(JsonSection, RefusesEveryUnknownKeyOfASectionByName) {
  EXPECT_THAT(
      MessageOf(R"({"s": {"x": 1, "y": 2, "z": 3}})",
                [](JsonSection& r) { r.Section("s", false, [](JsonSection& s) { s.Number("x", 0); }); }),
      HasSubstr("'job.json': unknown keys 's.y', 's.z' (see docs/test.md for the job keys)"));
}

TEST(JsonSection, ListsEveryProblemInOneMessageAfterTheFileName) {
  const json document = json::object();
  const JsonSection root(document, kContext);
  EXPECT_NO_THROW(root.ThrowIfProblems({}));
  try {
    root.ThrowIfProblems({"a = -1 violates > 0", "b = 7 violates <= 5"});
    ADD_FAILURE() << "no problems reported";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::kBadInput);
    EXPECT_EQ(std::string(e.what()), "test.job: 'job.json': a = -1 violates > 0; b = 7 violates <= 5");
  }
}

}  // namespace
}  // namespace arcwheel
