#pragma once
/// Text mesh formats read line by line: a line cursor over a file's bytes (LF, CRLF and CR line ends alike), a
/// splitter into blank-separated words, and number parsers that take a whole word or nothing.

#include <charconv>
#include <cstdint>
#include <string_view>
#include <system_error>
#include <vector>

namespace palpate {

/// Walks the lines of a text held in memory; a line end is LF, CRLF or a lone CR. Thread: one per reader.
class TextLines {
 public:
  /// Starts at byte `start` of text (which must outlive the cursor); line numbers count from first_line.
  explicit TextLines(std::string_view text, std::size_t start = 0, int64_t first_line = 1)
      : text_(text), pos_(start), next_number_(first_line) {}

  /// The next line without its end into *line; false at the end of the text.
  bool next(std::string_view* line) {
    if (pos_ >= text_.size()) return false;
    std::size_t end = pos_;
    while (end < text_.size() && text_[end] != '\n' && text_[end] != '\r') ++end;
    *line = text_.substr(pos_, end - pos_);
    if (end < text_.size() && text_[end] == '\r' && end + 1 < text_.size() && text_[end + 1] == '\n') ++end;
    pos_ = end + 1;
    number_ = next_number_++;
    return true;
  }

  /// The number of the line next() returned last (1-based).
  int64_t number() const { return number_; }
  /// The byte offset just past the line next() returned last (its line end included).
  std::size_t offset() const { return pos_; }

 private:
  std::string_view text_;
  std::size_t pos_;
  int64_t next_number_;
  int64_t number_ = 0;
};

/// Splits line at blanks (space, tab, vertical tab, form feed, NUL) into *words (cleared first).
inline void split_words(std::string_view line, std::vector<std::string_view>* words) {
  words->clear();
  auto blank = [](char c) { return c == ' ' || c == '\t' || c == '\v' || c == '\f' || c == '\0'; };
  std::size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && blank(line[i])) ++i;
    const std::size_t start = i;
    while (i < line.size() && !blank(line[i])) ++i;
    if (i > start) words->push_back(line.substr(start, i - start));
  }
}

/// A whole word as a real number (decimal or exponent form, an optional sign; "nan" and "inf" too, which the
/// caller checks); false when any character is left over.
inline bool parse_real(std::string_view word, double* out) {
  if (!word.empty() && word.front() == '+') word.remove_prefix(1);
  if (word.empty() || word.front() == '+') return false;
  const auto [end, ec] = std::from_chars(word.data(), word.data() + word.size(), *out);
  return ec == std::errc() && end == word.data() + word.size();
}

/// A whole word as a decimal integer (an optional sign); false when it is not one or does not fit int64.
inline bool parse_integer(std::string_view word, int64_t* out) {
  if (!word.empty() && word.front() == '+') word.remove_prefix(1);
  if (word.empty() || word.front() == '+') return false;
  const auto [end, ec] = std::from_chars(word.data(), word.data() + word.size(), *out);
  return ec == std::errc() && end == word.data() + word.size();
}

}  // namespace palpate
