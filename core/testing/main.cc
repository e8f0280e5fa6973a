// The main of every test binary. A folder's test files are compiled into one binary (in unity
// batches, so that GoogleTest, Eigen and nlohmann-json are parsed once a batch, not once a file);
// CTest still runs each file's tests as a test of its own, naming the file in ARCWHEEL_TEST_SOURCE.
// The binary then runs the tests defined in that file that GoogleTest's filter (--gtest_filter or
// GTEST_FILTER) also selects.

#include <fnmatch.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <string_view>
#include <vector>

namespace {

// GoogleTest's filter syntax: "POSITIVE[:POSITIVE...][-NEGATIVE[:NEGATIVE...]]", each a glob.
bool MatchesAny(std::string_view patterns, const std::string& name) {
  while (!patterns.empty()) {
    const std::size_t end = std::min(patterns.find(':'), patterns.size());
    const std::string pattern(patterns.substr(0, end));
    if (!pattern.empty() && fnmatch(pattern.c_str(), name.c_str(), 0) == 0) return true;
    patterns.remove_prefix(std::min(end + 1, patterns.size()));
  }
  return false;
}

bool FilterSelects(std::string_view filter, const std::string& name) {
  const std::size_t dash = std::min(filter.find('-'), filter.size());
  const std::string_view positive = filter.substr(0, dash);
  const std::string_view negative = filter.substr(std::min(dash + 1, filter.size()));
  return (positive.empty() || MatchesAny(positive, name)) && !MatchesAny(negative, name);
}

bool DefinedIn(const testing::TestInfo& test, std::string_view source) {
  const std::string_view file = test.file();
  return file == source || (file.size() > source.size() && file.ends_with(source) &&
                            file[file.size() - source.size() - 1] == '/');
}

std::string FullName(const testing::TestInfo& test) {
  return std::string(test.test_suite_name()) + "." + test.name();
}

// Restricts the run to the tests of `source` that `filter` selects, as an explicit filter ("-*"
// when it selects none). A message when the binary defines no test in `source` (a misnamed test
// file in CMake), or when one of them has the full name of a test in another file, which a filter
// by name would run too.
std::string RestrictToSource(const std::string& source) {
  const std::string filter = GTEST_FLAG_GET(filter);
  const testing::UnitTest& unit = *testing::UnitTest::GetInstance();
  std::vector<const testing::TestInfo*> tests;
  for (int s = 0; s < unit.total_test_suite_count(); ++s) {
    const testing::TestSuite& suite = *unit.GetTestSuite(s);
    for (int t = 0; t < suite.total_test_count(); ++t) tests.push_back(suite.GetTestInfo(t));
  }
  std::string selected;
  int defined = 0;
  for (const testing::TestInfo* test : tests) {
    if (!DefinedIn(*test, source)) continue;
    ++defined;
    const std::string name = FullName(*test);
    for (const testing::TestInfo* other : tests) {
      if (!DefinedIn(*other, source) && FullName(*other) == name) {
        return name + " is defined in both " + source + " and " + other->file() +
               ": give one a name of its own";
      }
    }
    if (!FilterSelects(filter, name)) continue;
    if (!selected.empty()) selected += ':';
    selected += name;
  }
  if (defined == 0) return "no test of this binary is defined in " + source + " (ARCWHEEL_TEST_SOURCE)";
  GTEST_FLAG_SET(filter, selected.empty() ? "-*" : selected);
  return "";
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  if (const char* source = std::getenv("ARCWHEEL_TEST_SOURCE"); source != nullptr && *source != '\0') {
    if (const std::string problem = RestrictToSource(source); !problem.empty()) {
      std::fprintf(stderr, "%s: %s\n", argv[0], problem.c_str());
      return 1;
    }
  }
  return RUN_ALL_TESTS();
}
