#include "frames/program_transform.h"

#include <fmt/core.h>

#include <array>
#include <cctype>
#include <charconv>
#include <cmath>
#include <optional>
#include <set>

#include "core/error.h"
#include "core/text_lines.h"

namespace arcwheel::frames {
namespace {

constexpr const char* kProgramTransformStage = "frames.program_transform";

struct Line {
  std::string_view body;    // without the line ending
  std::string_view ending;  // "\n", "\r\n" or "" (last line)
};

std::vector<Line> SplitLines(std::string_view text) {
  std::vector<Line> lines;
  size_t start = 0;
  while (start < text.size()) {
    const size_t newline = text.find('\n', start);
    if (newline == std::string_view::npos) {
      lines.push_back({text.substr(start), {}});
      break;
    }
    const size_t body_end = newline > start && text[newline - 1] == '\r' ? newline - 1 : newline;
    lines.push_back({text.substr(start, body_end - start), text.substr(body_end, newline + 1 - body_end)});
    start = newline + 1;
  }
  return lines;
}

[[noreturn]] void Refuse(const std::string& source, size_t line_index, const std::string& detail) {
  throw Error(ErrorCode::kBadInput, kProgramTransformStage,
              fmt::format("'{}' line {}: {}", source, line_index + 1, detail));
}

std::optional<double> ParseNumber(std::string_view text) {
  const std::string trimmed(TrimBlanks(text));
  const char* begin = trimmed.data();
  if (!trimmed.empty() && trimmed.front() == '+') ++begin;
  double value = 0.0;
  const auto [end, error] = std::from_chars(begin, trimmed.data() + trimmed.size(), value);
  if (trimmed.empty() || error != std::errc() || end != trimmed.data() + trimmed.size() ||
      !std::isfinite(value)) {
    return std::nullopt;
  }
  return value;
}

// ---------------------------------------------------------------- toolpath CSV

struct Triple {
  std::array<size_t, 3> columns{};
  bool direction = false;
};

std::vector<std::string> SplitRaw(std::string_view body) {
  std::vector<std::string> cells;
  size_t start = 0;
  while (true) {
    const size_t comma = body.find(',', start);
    cells.emplace_back(
        body.substr(start, comma == std::string_view::npos ? std::string_view::npos : comma - start));
    if (comma == std::string_view::npos) break;
    start = comma + 1;
  }
  return cells;
}

std::vector<Triple> FindTriples(const std::vector<std::string>& header, const std::string& source,
                                size_t line_index) {
  static const std::array<std::pair<std::array<const char*, 3>, bool>, 3> kTriples = {{
      {{"xw_mm", "yw_mm", "zw_mm"}, false},
      {{"x_mm", "y_mm", "z_mm"}, false},
      {{"nx", "ny", "nz"}, true},
  }};
  std::vector<Triple> triples;
  for (const auto& [names, direction] : kTriples) {
    Triple triple{.direction = direction};
    int found = 0;
    for (int k = 0; k < 3; ++k) {
      for (size_t c = 0; c < header.size(); ++c) {
        if (TrimBlanks(header[c]) == names[k]) {
          triple.columns[k] = c;
          ++found;
        }
      }
    }
    if (found == 3) triples.push_back(triple);
    if (found != 0 && found != 3) {
      Refuse(source, line_index,
             fmt::format("the header has only part of {},{},{}", names[0], names[1], names[2]));
    }
  }
  if (triples.empty())
    Refuse(source, line_index, "the header names no point columns (xw_mm.., x_mm.., nx..)");
  return triples;
}

ProgramTransformResult TransformToolpathCsv(std::string_view text, const Transform& transform,
                                            const std::string& source) {
  ProgramTransformResult result;
  std::vector<std::string> header;
  std::vector<Triple> triples;
  const auto lines = SplitLines(text);
  for (size_t index = 0; index < lines.size(); ++index) {
    const Line& line = lines[index];
    const std::string trimmed(TrimBlanks(line.body));
    if (trimmed.empty() || trimmed.front() == '#' || header.empty()) {
      if (!trimmed.empty() && trimmed.front() != '#') {
        header = SplitRaw(line.body);
        triples = FindTriples(header, source, index);
      }
      result.text.append(line.body).append(line.ending);
      continue;
    }
    std::vector<std::string> cells = SplitRaw(line.body);
    if (cells.size() != header.size()) {
      Refuse(source, index,
             fmt::format("{} cells, but the header has {} columns", cells.size(), header.size()));
    }
    for (const Triple& triple : triples) {
      Eigen::Vector3d v;
      for (int k = 0; k < 3; ++k) {
        const auto value = ParseNumber(cells[triple.columns[k]]);
        if (!value) {
          Refuse(source, index,
                 fmt::format("column '{}': '{}' is not a finite number",
                             TrimBlanks(header[triple.columns[k]]), cells[triple.columns[k]]));
        }
        v(k) = *value;
      }
      const Eigen::Vector3d mapped =
          triple.direction ? transform.ApplyToDirection(v) : transform.ApplyToPoint(v);
      for (int k = 0; k < 3; ++k) cells[triple.columns[k]] = fmt::format("{}", mapped(k));
      ++result.points_transformed;
    }
    std::string rewritten = cells.front();
    for (size_t c = 1; c < cells.size(); ++c) rewritten += "," + cells[c];
    if (rewritten != line.body) ++result.lines_changed;
    result.text.append(rewritten).append(line.ending);
  }
  if (header.empty())
    throw Error(ErrorCode::kBadInput, kProgramTransformStage, fmt::format("'{}' has no header row", source));
  return result;
}

// ---------------------------------------------------------------- machine programs

struct Token {
  std::string name;  // one upper-case letter for a word, else the keyword (upper case)
  bool has_number = false;
  double value = 0.0;
  size_t begin = 0;        // offset of the first letter in the line
  size_t value_begin = 0;  // offsets of the number (for words)
  size_t value_end = 0;
};

// Length of a literal number [+-]digits[.digits] or [+-].digits at `i`; 0 if none.
size_t NumberLength(std::string_view s, size_t i) {
  size_t j = i;
  if (j < s.size() && (s[j] == '+' || s[j] == '-')) ++j;
  size_t digits = 0;
  while (j < s.size() && std::isdigit(static_cast<unsigned char>(s[j]))) ++j, ++digits;
  if (j < s.size() && s[j] == '.') {
    ++j;
    while (j < s.size() && std::isdigit(static_cast<unsigned char>(s[j]))) ++j, ++digits;
  }
  return digits == 0 ? 0 : j - i;
}

std::vector<Token> Tokenize(std::string_view body, bool gcode) {
  std::vector<Token> tokens;
  size_t i = 0;
  while (i < body.size()) {
    const char c = body[i];
    if (c == ';') break;  // comment to the end of the line (both dialects)
    if (gcode && c == '(') {
      const size_t close = body.find(')', i);
      i = close == std::string_view::npos ? body.size() : close + 1;
      continue;
    }
    if (!std::isalpha(static_cast<unsigned char>(c))) {
      ++i;
      continue;
    }
    size_t j = i;
    while (j < body.size() && std::isalpha(static_cast<unsigned char>(body[j]))) ++j;
    Token token;
    token.begin = i;
    for (size_t k = i; k < j; ++k)
      token.name += static_cast<char>(std::toupper(static_cast<unsigned char>(body[k])));
    size_t k = j;
    if (j - i == 1) {
      while (k < body.size() && (body[k] == ' ' || body[k] == '\t')) ++k;
    }
    const size_t length = NumberLength(body, k);
    if (length > 0) {
      token.has_number = true;
      token.value_begin = k;
      token.value_end = k + length;
      std::from_chars(body.data() + k + (body[k] == '+' ? 1 : 0), body.data() + k + length, token.value);
      j = k + length;
    }
    tokens.push_back(std::move(token));
    i = j;
  }
  return tokens;
}

std::string FormatProgramNumber(double value, int decimals) {
  std::string text = fmt::format("{:.{}f}", value, decimals);
  if (text.find_first_not_of("-0.") == std::string::npos && text.front() == '-')
    text.erase(0, 1);  // no "-0.000"
  return text;
}

// The most digits after the point among the X/Y/Z words of the program (4 if none has a point).
int InputDecimals(const std::vector<Line>& lines, bool gcode) {
  int decimals = 0;
  for (const Line& line : lines) {
    for (const Token& token : Tokenize(line.body, gcode)) {
      if (!token.has_number || (token.name != "X" && token.name != "Y" && token.name != "Z")) continue;
      const std::string_view number =
          line.body.substr(token.value_begin, token.value_end - token.value_begin);
      const size_t point = number.find('.');
      if (point != std::string_view::npos)
        decimals = std::max(decimals, static_cast<int>(number.size() - point - 1));
    }
  }
  return decimals == 0 ? 4 : std::min(decimals, 12);
}

struct ProgramState {
  bool linear_motion = false;                   // G0/G1 (G-code) or LINEAR/RAPID/SPLINE (PMAC)
  std::array<std::optional<double>, 3> source;  // last commanded source position per axis
  std::array<std::optional<double>, 3> target;  // last written target position per axis
};

int GCode(const Token& token) { return static_cast<int>(std::lround(token.value * 10.0)); }

void CheckGcodeWords(const std::vector<Token>& tokens, ProgramState& state, const std::string& source,
                     size_t index) {
  static const std::set<int> kRefused = {20,  30,  910, 200, 280, 300, 530, 920, 680, 510, 730,
                                         740, 760, 810, 820, 830, 840, 850, 860, 870, 880, 890};
  for (const Token& token : tokens) {
    if (token.name == "G" && token.has_number) {
      const int code = GCode(token);
      if (kRefused.contains(code)) {
        Refuse(source, index,
               fmt::format("G{} cannot be transformed (only absolute G0/G1 moves are)", token.value));
      }
      if (code == 0 || code == 10) state.linear_motion = true;
    }
    if ((token.name == "I" || token.name == "J" || token.name == "K") && token.has_number) {
      Refuse(source, index, fmt::format("arc word {} cannot be transformed", token.name));
    }
  }
}

void CheckPmacWords(const std::vector<Token>& tokens, ProgramState& state, const std::string& source,
                    size_t index) {
  for (const Token& token : tokens) {
    const std::string& name = token.name;
    if (name == "INC") Refuse(source, index, "INC (incremental mode) cannot be transformed");
    if (name == "CIRCLE" || name == "CIR")
      Refuse(source, index, "circular moves (CIRCLE) cannot be transformed");
    if (name == "PVT") Refuse(source, index, "PVT moves cannot be transformed");
    if (name == "LINEAR" || name == "LIN" || name == "RAPID" || name == "RPD" || name == "SPLINE" ||
        name == "SPL") {
      state.linear_motion = true;
    }
  }
}

// Rewrites the X/Y/Z words of one line; returns the line unchanged if it has none.
std::string RewriteMove(std::string_view body, const std::vector<Token>& tokens, const Transform& transform,
                        ProgramState& state, const ProgramTransformOptions& options,
                        const std::string& source, size_t index, bool& moved) {
  std::array<const Token*, 3> words = {nullptr, nullptr, nullptr};
  for (const Token& token : tokens) {
    if (token.name == "A" || token.name == "B" || token.name == "C") {
      if (token.has_number)
        Refuse(source, index, fmt::format("rotary axis word {} cannot be transformed", token.name));
      continue;
    }
    if (token.name != "X" && token.name != "Y" && token.name != "Z") continue;
    const int axis = token.name[0] - 'X';
    if (!token.has_number)
      Refuse(source, index, fmt::format("{} is not followed by a literal number", token.name));
    if (words[axis] != nullptr) Refuse(source, index, fmt::format("{} appears twice", token.name));
    words[axis] = &token;
  }
  moved = words[0] || words[1] || words[2];
  if (!moved) return std::string(body);
  if (!state.linear_motion) Refuse(source, index, "X/Y/Z words before any G0/G1 motion mode");
  for (int b = 0; b < 3; ++b) {
    if (words[b]) state.source[b] = words[b]->value;
  }
  const Eigen::Matrix3d m = transform.scale * transform.linear;
  constexpr std::array<char, 3> kAxes = {'X', 'Y', 'Z'};
  std::array<std::optional<double>, 3> write;
  for (int a = 0; a < 3; ++a) {
    bool touched = words[a] != nullptr;
    bool known = true;
    double value = transform.translation_mm(a);
    for (int b = 0; b < 3; ++b) {
      if (std::abs(m(a, b)) <= 1e-12 && a != b) continue;
      touched = touched || words[b] != nullptr;
      if (!state.source[b]) {
        known = false;
        continue;
      }
      value += m(a, b) * *state.source[b];
    }
    if (!touched) continue;
    if (!known) {
      Refuse(source, index,
             fmt::format("the new {} needs a source position not given before this line: give a full "
                         "X Y Z position first",
                         kAxes[a]));
    }
    if (words[a] || !state.target[a] ||
        FormatProgramNumber(*state.target[a], options.decimals) !=
            FormatProgramNumber(value, options.decimals)) {
      write[a] = value;
      state.target[a] = value;
    }
  }
  // Replace present words from the back so that earlier offsets stay valid, then insert new ones.
  std::string out(body);
  size_t insert_at = 0;
  size_t first_word = body.size();
  for (const Token* word : words) {
    if (word)
      insert_at = std::max(insert_at, word->value_end), first_word = std::min(first_word, word->begin);
  }
  std::string added;
  // Dense programs ("G1X10Y20") get dense insertions; spaced ones a space.
  const bool dense = first_word > 0 && body[first_word - 1] != ' ' && body[first_word - 1] != '\t';
  const std::string separator = dense ? "" : " ";
  for (int a = 0; a < 3; ++a) {
    if (write[a] && !words[a])
      added += separator + kAxes[a] + FormatProgramNumber(*write[a], options.decimals);
  }
  out.insert(insert_at, added);
  std::array<int, 3> order = {0, 1, 2};
  std::sort(order.begin(), order.end(), [&](int l, int r) {
    const size_t lb = words[l] ? words[l]->value_begin : 0, rb = words[r] ? words[r]->value_begin : 0;
    return lb > rb;
  });
  for (int a : order) {
    if (!words[a]) continue;
    out.replace(words[a]->value_begin, words[a]->value_end - words[a]->value_begin,
                FormatProgramNumber(*write[a], options.decimals));
  }
  return out;
}

bool IsOpenProg(const std::vector<Token>& tokens) {
  for (size_t i = 0; i + 1 < tokens.size(); ++i) {
    if (tokens[i].name == "OPEN" && (tokens[i + 1].name == "PROG" || tokens[i + 1].name == "PROGRAM"))
      return true;
  }
  return false;
}

bool IsClose(const std::vector<Token>& tokens) {
  return std::any_of(tokens.begin(), tokens.end(), [](const Token& t) { return t.name == "CLOSE"; });
}

ProgramTransformResult TransformMachineProgram(std::string_view text, bool gcode, const Transform& transform,
                                               const std::string& source, ProgramTransformOptions options) {
  ProgramTransformResult result;
  ProgramState state;
  bool inside = gcode;  // G-code: the whole file; PMAC: between OPEN PROG and CLOSE
  const auto lines = SplitLines(text);
  if (options.decimals < 0) options.decimals = InputDecimals(lines, gcode);
  for (size_t index = 0; index < lines.size(); ++index) {
    const Line& line = lines[index];
    const std::vector<Token> tokens = Tokenize(line.body, gcode);
    std::string rewritten(line.body);
    if (!gcode && IsOpenProg(tokens)) {
      inside = true;
      state = ProgramState{};
      state.linear_motion = true;  // PMAC programs start in LINEAR mode
    } else if (!gcode && inside && IsClose(tokens)) {
      inside = false;
    } else if (inside) {
      if (gcode) {
        CheckGcodeWords(tokens, state, source, index);
      } else {
        CheckPmacWords(tokens, state, source, index);
      }
      bool moved = false;
      rewritten = RewriteMove(line.body, tokens, transform, state, options, source, index, moved);
      if (moved) ++result.points_transformed;
    }
    if (rewritten != line.body) ++result.lines_changed;
    result.text.append(rewritten).append(line.ending);
  }
  if (!gcode && result.points_transformed == 0) {
    throw Error(ErrorCode::kBadInput, kProgramTransformStage,
                fmt::format("'{}' has no X/Y/Z move between OPEN PROG and CLOSE", source));
  }
  return result;
}

}  // namespace

std::vector<std::string> ProgramTransformOptions::Problems() const {
  if (decimals == -1 || (decimals >= 1 && decimals <= 12)) return {};
  return {fmt::format("--decimals = {} violates -1 or [1, 12]", decimals)};
}

ProgramKind ParseProgramKind(std::string_view name) {
  if (name == "csv") return ProgramKind::kToolpathCsv;
  if (name == "gcode") return ProgramKind::kGcode;
  if (name == "pmac") return ProgramKind::kPmac;
  throw Error(ErrorCode::kInvalidOption, kProgramTransformStage,
              fmt::format("unknown file format '{}' (expected csv, gcode or pmac)", name));
}

ProgramKind DetectProgramKind(const std::filesystem::path& path, std::string_view text) {
  std::string extension = path.extension().string();
  for (char& c : extension) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  if (extension == ".csv") return ProgramKind::kToolpathCsv;
  if (extension == ".pmc" || extension == ".pmac") return ProgramKind::kPmac;
  static const std::set<std::string> kGcode = {".nc", ".ngc", ".gcode", ".tap", ".iso", ".cnc"};
  if (kGcode.contains(extension)) return ProgramKind::kGcode;
  std::string upper(text.substr(0, 1 << 16));
  for (char& c : upper) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  if (upper.find("OPEN PROG") != std::string::npos) return ProgramKind::kPmac;
  if (upper.find("X_MM") != std::string::npos && upper.find(',') != std::string::npos)
    return ProgramKind::kToolpathCsv;
  return ProgramKind::kGcode;
}

ProgramTransformResult TransformProgram(std::string_view text, ProgramKind kind, const Transform& transform,
                                        const std::string& source_name,
                                        const ProgramTransformOptions& options) {
  ThrowIfProblems(ErrorCode::kInvalidOption, kProgramTransformStage, options.Problems());
  switch (kind) {
    case ProgramKind::kToolpathCsv:
      return TransformToolpathCsv(text, transform, source_name);
    case ProgramKind::kGcode:
      return TransformMachineProgram(text, true, transform, source_name, options);
    case ProgramKind::kPmac:
      return TransformMachineProgram(text, false, transform, source_name, options);
  }
  return {};
}

}  // namespace arcwheel::frames
