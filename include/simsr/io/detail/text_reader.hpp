#pragma once
/// \file
/// Shared helpers of the text mesh readers/writers (obj, msh, tetgen, medit): a line cursor that
/// knows its 1-based line number, strict number parsing (std::from_chars; whole token, no NaN/inf),
/// count validation against the bytes left (so a hostile count cannot make a reader allocate
/// gigabytes) and shortest round-trip number formatting for the writers.
///
/// Every failure is a simsr::ParseError(file, line, message) naming the offending line.

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <string>
#include <string_view>
#include <system_error>
#include <type_traits>
#include <vector>

#include "../../core/error.hpp"
#include "../../core/types.hpp"
#include "../atomic_file.hpp"

namespace simsr::io::detail {

/// Reads a whole file into memory (binary, unchanged). ParseError(path, 0, ...) when it cannot be read.
inline std::string read_text_file(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw ParseError(path.string(), 0, "cannot open file for reading");
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (in.bad()) throw ParseError(path.string(), 0, "read error");
  return text;
}

/// Writes `text` to `path` (replacing it atomically, io/atomic_file.hpp). WriteError when it cannot
/// be written.
inline void write_text_file(const std::filesystem::path& path, std::string_view text) { write_file_atomic(path, text); }

/// A token made printable for an error message: at most 40 characters, control bytes as '?'.
inline std::string quote(std::string_view tok) {
  std::string s = "'";
  for (std::size_t i = 0; i < tok.size() && i < 40; ++i) {
    const unsigned char c = static_cast<unsigned char>(tok[i]);
    s += (c < 32 || c >= 127) ? '?' : static_cast<char>(c);
  }
  if (tok.size() > 40) s += "...";
  return s + "'";
}

inline bool is_space(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f'; }

/// `s` without leading and trailing blanks.
inline std::string_view trim(std::string_view s) {
  while (!s.empty() && is_space(s.front())) s.remove_prefix(1);
  while (!s.empty() && is_space(s.back())) s.remove_suffix(1);
  return s;
}

/// Whitespace-separated tokens of one line, in order.
class Tokens {
 public:
  explicit Tokens(std::string_view line) : rest_(line) {}
  /// Next token into `tok`; false when none is left.
  bool next(std::string_view& tok) {
    while (!rest_.empty() && is_space(rest_.front())) rest_.remove_prefix(1);
    if (rest_.empty()) return false;
    std::size_t n = 0;
    while (n < rest_.size() && !is_space(rest_[n])) ++n;
    tok = rest_.substr(0, n);
    rest_.remove_prefix(n);
    return true;
  }
  /// What has not been consumed yet.
  std::string_view rest() const { return rest_; }

 private:
  std::string_view rest_;
};

/// All tokens of `line` into `out` (cleared first; reuse it across lines to avoid allocation).
inline void split(std::string_view line, std::vector<std::string_view>& out) {
  out.clear();
  Tokens t(line);
  std::string_view tok;
  while (t.next(tok)) out.push_back(tok);
}

/// Strict integer parse of a whole token (optional leading '+'); false on junk or overflow.
template <class I>
bool parse_int(std::string_view tok, I& out) {
  static_assert(std::is_integral_v<I>);
  if (tok.size() > 1 && tok[0] == '+' && tok[1] != '-' && tok[1] != '+') tok.remove_prefix(1);
  if (tok.empty()) return false;
  const auto r = std::from_chars(tok.data(), tok.data() + tok.size(), out);
  return r.ec == std::errc() && r.ptr == tok.data() + tok.size();
}

/// Strict real parse of a whole token (decimal or scientific, optional leading '+'); false on junk,
/// overflow/underflow of double, NaN, infinity, or a value not finite in S.
template <class S>
bool parse_real(std::string_view tok, S& out) {
  if (tok.size() > 1 && tok[0] == '+' && tok[1] != '-' && tok[1] != '+') tok.remove_prefix(1);
  if (tok.empty()) return false;
  double v = 0;
  const auto r = std::from_chars(tok.data(), tok.data() + tok.size(), v, std::chars_format::general);
  if (r.ptr != tok.data() + tok.size()) return false;
  if (r.ec == std::errc::result_out_of_range) {
    // Overflow or underflow: strtod tells them apart (±HUGE_VAL vs. a tiny value, as strtod rounds).
    const std::string copy(tok);
    v = std::strtod(copy.c_str(), nullptr);
    if (std::isinf(v)) return false;
  } else if (r.ec != std::errc()) {
    return false;
  }
  if (!std::isfinite(v)) return false;
  const S s = static_cast<S>(v);
  if (!std::isfinite(s)) return false;
  out = s;
  return true;
}

/// A read position in a text held in memory: iterates lines (ending in "\n", "\r\n" or the end of
/// text) and knows the current 1-based line number, for error messages.
class LineCursor {
 public:
  /// `name` is what error messages call the text (usually its path).
  LineCursor(std::string_view text, std::string name) : text_(text), name_(std::move(name)) {}

  /// Advances to the next line; false at the end of text. A NUL byte is an error (binary data).
  bool next() {
    if (pos_ >= text_.size()) {
      line_ = {};
      at_end_ = true;
      return false;
    }
    const std::size_t end = text_.find('\n', pos_);
    const std::size_t stop = end == std::string_view::npos ? text_.size() : end;
    line_ = text_.substr(pos_, stop - pos_);
    pos_ = end == std::string_view::npos ? text_.size() : end + 1;
    ++line_number_;
    if (!line_.empty() && line_.back() == '\r') line_.remove_suffix(1);
    if (std::memchr(line_.data(), '\0', line_.size()) != nullptr) fail("NUL byte: binary data in a text file");
    return true;
  }

  /// Advances to the next line that is not blank once `comment` (0: none) and what follows it are
  /// removed; line() is then that trimmed content. False at the end of text.
  bool next_content(char comment = '#') {
    while (next()) {
      std::string_view s = line_;
      if (comment != 0) {
        const std::size_t c = s.find(comment);
        if (c != std::string_view::npos) s = s.substr(0, c);
      }
      s = trim(s);
      if (!s.empty()) {
        line_ = s;
        return true;
      }
    }
    return false;
  }

  /// Like next_content, but a missing line is an error naming what was expected.
  void require_content(const std::string& expected, char comment = '#') {
    if (!next_content(comment)) fail_eof(expected);
  }

  std::string_view line() const { return line_; }
  std::int64_t line_number() const { return line_number_; }
  /// Bytes after the current line.
  std::size_t bytes_left() const { return text_.size() - pos_; }
  const std::string& name() const { return name_; }

  [[noreturn]] void fail(const std::string& message) const { throw ParseError(name_, std::max<std::int64_t>(line_number_, 1), message); }
  [[noreturn]] void fail_at(std::int64_t line, const std::string& message) const { throw ParseError(name_, std::max<std::int64_t>(line, 1), message); }
  /// The text ended early: reported at the last line read (1 for an empty text).
  [[noreturn]] void fail_eof(const std::string& expected) const {
    throw ParseError(name_, std::max<std::int64_t>(line_number_, 1), "unexpected end of file: expected " + expected);
  }

  /// Integer token or an error naming `what`.
  template <class I = std::int64_t>
  I integer(std::string_view tok, const std::string& what) const {
    I v{};
    if (!parse_int(tok, v)) fail("malformed or out-of-range " + what + " " + quote(tok));
    return v;
  }

  /// Finite real token or an error naming `what`.
  template <class S = double>
  S real(std::string_view tok, const std::string& what) const {
    S v{};
    if (!parse_real(tok, v)) fail("malformed or non-finite " + what + " " + quote(tok));
    return v;
  }

  /// A declared item count: an integer ≥ 0 whose items, each at least `min_bytes_per_item` bytes
  /// long with its line end, fit in `bytes_available` (default: the bytes after this line). Guards
  /// every reserve. A line of k tokens takes at least 2k bytes.
  std::int64_t count(std::string_view tok, std::size_t min_bytes_per_item, const std::string& what,
                     std::size_t bytes_available = std::numeric_limits<std::size_t>::max()) const {
    const auto n = integer<std::int64_t>(tok, "count of " + what);
    check_count(n, min_bytes_per_item, what, bytes_available);
    return n;
  }

  /// Validates an already parsed count as count() does.
  void check_count(std::int64_t n, std::size_t min_bytes_per_item, const std::string& what,
                   std::size_t bytes_available = std::numeric_limits<std::size_t>::max()) const {
    if (n < 0) fail("negative count of " + what + " (" + std::to_string(n) + ")");
    if (bytes_available == std::numeric_limits<std::size_t>::max()) bytes_available = bytes_left();
    const std::size_t per = std::max<std::size_t>(min_bytes_per_item, 1);
    if (static_cast<std::uint64_t>(n) > (bytes_available + 1) / per)  // +1: the last line may lack its '\n'
      fail("declares " + std::to_string(n) + " " + what + " but only " + std::to_string(bytes_available) +
           " bytes follow (truncated file or absurd count)");
    if (n > std::numeric_limits<VIndex>::max()) fail("too many " + what + " (" + std::to_string(n) + ")");
  }

  /// A vertex reference: integer token minus `base`, required in [0, n).
  VIndex index(std::string_view tok, std::int64_t base, std::int64_t n, const std::string& what) const {
    const auto v = integer<std::int64_t>(tok, what);
    if (v < base || v - base >= n)
      fail(what + " " + std::to_string(v) + " out of range [" + std::to_string(base) + ", " + std::to_string(base + n) + ")");
    return static_cast<VIndex>(v - base);
  }

 private:
  std::string_view text_;
  std::string name_;
  std::size_t pos_ = 0;
  std::string_view line_;
  std::int64_t line_number_ = 0;
  bool at_end_ = false;
};

/// Whitespace-separated tokens across lines (free-format files such as MEDIT); `comment` starts a
/// comment that runs to the end of its line. The cursor's line number is that of the last token.
class TokenStream {
 public:
  TokenStream(LineCursor& cursor, char comment) : cur_(cursor), comment_(comment) {}

  /// Next token; false at the end of text.
  bool next(std::string_view& tok) {
    while (true) {
      if (rest_.next(tok)) return true;
      if (!cur_.next_content(comment_)) return false;
      rest_ = Tokens(cur_.line());
    }
  }
  /// Next token, or an end-of-file error naming what was expected.
  std::string_view expect(const std::string& what) {
    std::string_view tok;
    if (!next(tok)) cur_.fail_eof(what);
    return tok;
  }
  /// Bytes not consumed yet (rest of the current line and all later lines).
  std::size_t bytes_left() const { return cur_.bytes_left() + rest_.rest().size(); }
  LineCursor& cursor() { return cur_; }

 private:
  LineCursor& cur_;
  char comment_;
  Tokens rest_{std::string_view{}};
};

/// Appends the shortest decimal text that reads back to exactly `v` (round trip exact).
template <class S>
void append_real(std::string& out, S v) {
  char buf[64];
  const auto r = std::to_chars(buf, buf + sizeof buf, v);
  out.append(buf, r.ptr);
}

/// Appends an integer in decimal.
template <class I>
void append_int(std::string& out, I v) {
  char buf[32];
  const auto r = std::to_chars(buf, buf + sizeof buf, v);
  out.append(buf, r.ptr);
}

/// Rejects a non-finite coordinate before it is written (a writer must not emit what its reader rejects).
template <class S>
void check_finite_points(const Points<S>& V) {
  for (Index i = 0; i < V.rows(); ++i)
    for (int k = 0; k < 3; ++k)
      if (!std::isfinite(V(i, k))) throw MeshError("vertex", i, "non-finite coordinate");
}

/// Rejects an index outside [0, n) before it is written.
template <class Derived>
void check_indices(const Eigen::MatrixBase<Derived>& E, Index n, const std::string& kind) {
  for (Index r = 0; r < E.rows(); ++r)
    for (Index c = 0; c < E.cols(); ++c)
      if (E(r, c) < 0 || E(r, c) >= n)
        throw MeshError(kind, r, "vertex index " + std::to_string(E(r, c)) + " outside [0, " + std::to_string(n) + ")");
}

}  // namespace simsr::io::detail
