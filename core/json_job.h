#pragma once
// Reading a JSON job file (grinding's and polishing's) by key: typed getters that name the file,
// the dotted key, what was expected and what was given; a record of the job as used, with every
// default filled in; and a refusal of any key nobody asked for.
//
// Every failure throws Error{kBadInput, stage} whose message reads
//   '<file>': key '<dotted.key>' expected <what>, got <value as written>
// (a missing key is "got nothing"). Range checks of the values belong to the options structs'
// Problems(); ThrowIfProblems reports them all at once.

#include <cstddef>
#include <functional>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <set>
#include <string>
#include <vector>

namespace arcwheel {

// What every section of one job shares: the file named in messages, the stage id that prefixes
// them, and the page that documents the keys.
struct JsonJobContext {
  std::string file;
  std::string stage;
  std::string docs_page;  // e.g. "docs/grinding.md"
};

// One JSON object of a job. A section without an object (an absent optional section) answers
// every getter with its default.
class JsonSection {
 public:
  // The root of a parsed document; `document` must outlive the section and its children.
  JsonSection(const nlohmann::json& document, JsonJobContext context);

  // True if `key` is present and not null.
  [[nodiscard]] bool Has(const std::string& key) const;
  // "prefix.key", or "key" at the root; the section's own name for an empty key.
  [[nodiscard]] std::string Dotted(const std::string& key) const;

  // A finite number; `fallback` when absent.
  double Number(const std::string& key, double fallback);
  double RequiredNumber(const std::string& key);
  std::optional<double> OptionalNumber(const std::string& key);
  // A whole number within [low, high], checked as a number first so that 2.5 is refused rather
  // than used as 2 and a value beyond int's range is never cast.
  int WholeNumber(const std::string& key, int fallback, int low, int high);
  // A JSON integer (2.0 is refused) that fits an int.
  int Integer(const std::string& key, int fallback);
  bool Boolean(const std::string& key, bool fallback);
  std::string String(const std::string& key, const std::string& fallback);
  std::optional<std::string> OptionalString(const std::string& key);
  // One of `choices`; the first is the default.
  std::string Choice(const std::string& key, const std::vector<std::string>& choices);
  // An array of fallback.size() finite numbers; `fallback` when absent.
  std::vector<double> Numbers(const std::string& key, std::vector<double> fallback);
  // An array of exactly `count` finite numbers that must be present.
  std::vector<double> RequiredNumbers(const std::string& key, std::size_t count);
  // The raw value (present), for shapes the getters do not cover; recorded as given.
  const nlohmann::json& Raw(const std::string& key);

  // Reads the object at `key` with `read`, refuses its unknown keys and records it. An absent
  // optional section is read as empty (every default); an absent required one is refused.
  void Section(const std::string& key, bool required, const std::function<void(JsonSection&)>& read);
  // Reads every element of the array at `key` (present, non-empty objects expected: `what` says
  // what an element holds) with `read`, refusing unknown keys in each, and records the array.
  void Elements(const std::string& key, const std::string& what,
                const std::function<void(JsonSection&)>& read);

  // Records a value the job did not give but the run used (a default taken from elsewhere).
  void SetResolved(const std::string& key, const nlohmann::json& value);
  // Refuses the keys nobody read, naming them all.
  void Finish() const;
  // The section as used, every default filled in.
  [[nodiscard]] const nlohmann::json& resolved() const { return resolved_; }

  // Throws "'<file>': key '<dotted.key>' <detail>" (for checks that are not a getter's).
  [[noreturn]] void Fail(const std::string& key, const std::string& detail) const;
  // Throws "'<file>': key '<dotted.key>' expected <expected>, got <value as written>".
  [[noreturn]] void Expected(const std::string& key, const std::string& expected) const;
  // Throws one Error "'<file>': <every problem, JoinProblems>", if there are any.
  void ThrowIfProblems(const std::vector<std::string>& problems) const;

 private:
  JsonSection(const nlohmann::json* object, std::string prefix,
              std::shared_ptr<const JsonJobContext> context);
  [[nodiscard]] const nlohmann::json& At(const std::string& key) const;
  double FiniteNumber(const std::string& key, const std::string& expected) const;

  const nlohmann::json* object_;
  std::string prefix_;
  std::shared_ptr<const JsonJobContext> context_;
  std::set<std::string> used_;
  nlohmann::json resolved_ = nlohmann::json::object();
};

}  // namespace arcwheel
