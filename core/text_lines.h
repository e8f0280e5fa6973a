#pragma once
// Walks a text buffer line by line, for the readers of text exports that name a bad line by its
// number.

#include <cstddef>
#include <string_view>

namespace arcwheel {

// `text` without its leading and trailing blanks (spaces, tabs, a stray carriage return).
inline std::string_view TrimBlanks(std::string_view text) {
  const std::size_t first = text.find_first_not_of(" \t\r");
  if (first == std::string_view::npos) return {};
  return text.substr(first, text.find_last_not_of(" \t\r") - first + 1);
}

// The lines of `text` in order, LF or CRLF endings taken off, counted from 1; a UTF-8 byte order
// mark (as spreadsheets and Windows tools write) is skipped.
class TextLines {
 public:
  explicit TextLines(std::string_view text) : text_(text) {
    if (text_.starts_with("\xEF\xBB\xBF")) text_.remove_prefix(3);
  }

  // The next line into `line`; false after the last.
  bool Next(std::string_view& line) {
    if (position_ >= text_.size()) return false;
    const std::size_t end = text_.find('\n', position_);
    const std::size_t stop = end == std::string_view::npos ? text_.size() : end;
    line = text_.substr(position_, stop - position_);
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    position_ = end == std::string_view::npos ? text_.size() : end + 1;
    ++number_;
    return true;
  }

  // The number of the line Next gave last (0 before the first).
  [[nodiscard]] std::size_t number() const { return number_; }

 private:
  std::string_view text_;
  std::size_t position_ = 0;
  std::size_t number_ = 0;
};

}  // namespace arcwheel
