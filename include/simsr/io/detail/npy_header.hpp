#pragma once
/// \file
/// The .npy format's dtype descriptors and header (magic, version, Python dict literal): a parser
/// hardened against hostile input (every length is checked against the bytes at hand before use)
/// and the matching emitter. See https://numpy.org/doc/stable/reference/generated/numpy.lib.format.html

#include <bit>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <limits>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "../../core/error.hpp"

namespace simsr::io {

/// Element kinds of the supported dtypes (numpy's `dtype.kind`).
enum class NpyKind : char { Bool = 'b', Int = 'i', UInt = 'u', Float = 'f', Unicode = 'U' };

/// A numpy dtype restricted to what simsr reads: bool, int8..int64, uint8..uint64, float32/64 in
/// either byte order, and fixed-width unicode `U{n}` (UCS-4, `itemsize` = 4n bytes).
struct NpyDType {
  NpyKind kind = NpyKind::Float;
  std::size_t itemsize = 8;  ///< bytes per element
  bool big_endian = false;   ///< byte order of the stored elements (irrelevant when itemsize is 1)

  /// numpy's `dtype.str`, e.g. `<f8`, `|b1`, `>i4`, `<U16`.
  std::string descr() const {
    std::string s;
    if (kind == NpyKind::Bool || (itemsize == 1 && kind != NpyKind::Unicode))
      s += '|';
    else
      s += big_endian ? '>' : '<';
    s += static_cast<char>(kind);
    s += std::to_string(kind == NpyKind::Unicode ? itemsize / 4 : itemsize);
    return s;
  }
  /// numpy's `dtype.name`-like readable name: `float64`, `uint8`, `bool`, `<U16`.
  std::string name() const {
    switch (kind) {
      case NpyKind::Bool: return "bool";
      case NpyKind::Int: return "int" + std::to_string(itemsize * 8);
      case NpyKind::UInt: return "uint" + std::to_string(itemsize * 8);
      case NpyKind::Float: return "float" + std::to_string(itemsize * 8);
      case NpyKind::Unicode: return "<U" + std::to_string(itemsize / 4);
    }
    return "?";
  }
  /// Whether stored elements must be byte-swapped on this host.
  bool needs_swap() const {
    const bool host_big = std::endian::native == std::endian::big;
    return itemsize > 1 && big_endian != host_big;
  }
  bool operator==(const NpyDType& o) const {
    return kind == o.kind && itemsize == o.itemsize && (itemsize == 1 ? true : big_endian == o.big_endian);
  }

  /// Parses a descriptor string; nullopt when it is not one of the supported dtypes.
  static std::optional<NpyDType> parse(std::string_view d) {
    if (d.size() < 2 || d.size() > 24) return std::nullopt;
    char order = '=';
    if (d[0] == '<' || d[0] == '>' || d[0] == '|' || d[0] == '=') {
      order = d[0];
      d.remove_prefix(1);
    }
    if (d.size() < 2) return std::nullopt;
    const char k = d[0];
    std::uint64_t n = 0;
    for (std::size_t i = 1; i < d.size(); ++i) {
      if (d[i] < '0' || d[i] > '9' || n > (1u << 24)) return std::nullopt;
      n = n * 10 + static_cast<std::uint64_t>(d[i] - '0');
    }
    NpyDType t;
    t.big_endian = order == '>' || (order == '=' && std::endian::native == std::endian::big);
    switch (k) {
      case 'b':
        if (n != 1) return std::nullopt;
        t.kind = NpyKind::Bool;
        break;
      case 'i':
      case 'u':
        if (n != 1 && n != 2 && n != 4 && n != 8) return std::nullopt;
        t.kind = k == 'i' ? NpyKind::Int : NpyKind::UInt;
        break;
      case 'f':
        if (n != 4 && n != 8) return std::nullopt;
        t.kind = NpyKind::Float;
        break;
      case 'U':
        if (n == 0 || n > (1u << 24)) return std::nullopt;
        t.kind = NpyKind::Unicode;
        t.itemsize = static_cast<std::size_t>(n) * 4;
        if (order == '|') return std::nullopt;
        return t;
      default: return std::nullopt;
    }
    t.itemsize = static_cast<std::size_t>(n);
    if (order == '|' && t.itemsize != 1) return std::nullopt;
    if (t.itemsize == 1) t.big_endian = false;
    return t;
  }

  /// The dtype of C++ element type T (native byte order).
  template <class T>
  static NpyDType of() {
    NpyDType t;
    t.itemsize = sizeof(T);
    t.big_endian = sizeof(T) > 1 && std::endian::native == std::endian::big;
    if constexpr (std::is_same_v<T, bool>) {
      t.kind = NpyKind::Bool;
    } else if constexpr (std::is_floating_point_v<T>) {
      static_assert(sizeof(T) == 4 || sizeof(T) == 8, "npy: only float32 and float64 are supported");
      t.kind = NpyKind::Float;
    } else if constexpr (std::is_integral_v<T>) {
      static_assert(sizeof(T) <= 8, "npy: integers wider than 64 bits are not supported");
      t.kind = std::is_signed_v<T> ? NpyKind::Int : NpyKind::UInt;
    } else {
      static_assert(std::is_arithmetic_v<T>, "npy: element type must be bool, an integer or float/double");
    }
    return t;
  }
};

namespace detail {

inline constexpr char npy_magic[6] = {'\x93', 'N', 'U', 'M', 'P', 'Y'};
/// Largest header dict accepted. numpy itself refuses headers above 10000 bytes by default; the
/// supported dtypes never need more than a few hundred.
inline constexpr std::size_t npy_max_header = 1u << 16;

/// Result of parsing the preamble: where the dict starts and how long it is.
struct NpyPreamble {
  int major = 1;
  std::size_t dict_offset = 10;
  std::size_t dict_length = 0;
  std::size_t data_offset() const { return dict_offset + dict_length; }
};

/// Parsed header dict.
struct NpyHeader {
  NpyDType dtype;
  bool fortran_order = false;
  std::vector<std::int64_t> shape;
  std::size_t data_offset = 0;
  std::uint64_t count = 1;       ///< product of the shape
  std::uint64_t data_bytes = 0;  ///< count × itemsize
};

/// Reads the magic, version and header length from the first `n` bytes (at least 12 are looked at
/// when present). Throws ParseError when the preamble is invalid or `available` total bytes cannot
/// hold the announced header.
inline NpyPreamble npy_parse_preamble(const unsigned char* p, std::size_t n, std::uint64_t available,
                                      const std::string& file) {
  if (n < 8 || std::memcmp(p, npy_magic, 6) != 0) {
    if (n < 6 && std::memcmp(p, npy_magic, n) == 0)
      throw ParseError(file, 0, "byte " + std::to_string(n) + ": truncated .npy magic");
    throw ParseError(file, 0, "byte 0: bad magic, not a .npy file (expected \\x93NUMPY)");
  }
  NpyPreamble pre;
  pre.major = p[6];
  if (pre.major < 1 || pre.major > 3 || p[7] != 0)
    throw ParseError(file, 0,
                     "byte 6: unsupported .npy version " + std::to_string(p[6]) + "." + std::to_string(p[7]));
  if (pre.major == 1) {
    if (n < 10) throw ParseError(file, 0, "byte 8: truncated header length");
    pre.dict_offset = 10;
    pre.dict_length = static_cast<std::size_t>(p[8]) | static_cast<std::size_t>(p[9]) << 8;
  } else {
    if (n < 12) throw ParseError(file, 0, "byte 8: truncated header length");
    pre.dict_offset = 12;
    const std::uint64_t len = static_cast<std::uint64_t>(p[8]) | static_cast<std::uint64_t>(p[9]) << 8 |
                              static_cast<std::uint64_t>(p[10]) << 16 | static_cast<std::uint64_t>(p[11]) << 24;
    if (len > npy_max_header)
      throw ParseError(file, 0, "byte 8: header length " + std::to_string(len) + " exceeds the limit of " +
                                    std::to_string(npy_max_header) + " bytes");
    pre.dict_length = static_cast<std::size_t>(len);
  }
  if (pre.dict_offset + pre.dict_length > available)
    throw ParseError(file, 0,
                     "byte 8: header length " + std::to_string(pre.dict_length) + " but only " +
                         std::to_string(available > pre.dict_offset ? available - pre.dict_offset : 0) +
                         " bytes follow (truncated file)");
  return pre;
}

/// Minimal parser for the Python literal numpy writes:
/// `{'descr': '<f8', 'fortran_order': False, 'shape': (3, 4), }` plus space padding and '\n'.
class NpyDictParser {
 public:
  NpyDictParser(std::string_view s, std::size_t base, const std::string& file) : s_(s), base_(base), file_(file) {}

  NpyHeader parse() {
    NpyHeader h;
    bool have_descr = false, have_order = false, have_shape = false;
    ws();
    expect('{');
    for (;;) {
      ws();
      if (peek() == '}') {
        ++i_;
        break;
      }
      const std::string key = string_literal();
      ws();
      expect(':');
      ws();
      if (key == "descr") {
        if (have_descr) fail("duplicate key 'descr'");
        if (peek() == '[') fail("structured dtypes (descr is a list) are not supported");
        const std::size_t at = i_;
        const std::string d = string_literal();
        const auto t = NpyDType::parse(d);
        if (!t) fail_at(at, "unsupported dtype '" + printable(d) + "'");
        h.dtype = *t;
        have_descr = true;
      } else if (key == "fortran_order") {
        if (have_order) fail("duplicate key 'fortran_order'");
        h.fortran_order = boolean();
        have_order = true;
      } else if (key == "shape") {
        if (have_shape) fail("duplicate key 'shape'");
        h.shape = tuple();
        have_shape = true;
      } else {
        fail("unexpected key '" + printable(key) + "' in header dict");
      }
      ws();
      if (peek() == ',') {
        ++i_;
        continue;
      }
      ws();
      if (peek() == '}') {
        ++i_;
        break;
      }
      fail("expected ',' or '}' in header dict");
    }
    if (!have_descr || !have_order || !have_shape)
      fail_at(0, std::string("header dict lacks key '") +
                     (!have_descr ? "descr" : !have_order ? "fortran_order" : "shape") + "'");
    for (; i_ < s_.size(); ++i_)
      if (s_[i_] != ' ' && s_[i_] != '\n' && s_[i_] != '\t' && s_[i_] != '\r' && s_[i_] != '\0')
        fail("unexpected characters after the header dict");
    std::uint64_t count = 1;
    for (const std::int64_t d : h.shape)
      if (__builtin_mul_overflow(count, static_cast<std::uint64_t>(d), &count))
        fail_at(0, "shape " + shape_text(h.shape) + ": element count overflows 64 bits");
    std::uint64_t bytes = 0;
    if (__builtin_mul_overflow(count, static_cast<std::uint64_t>(h.dtype.itemsize), &bytes) ||
        bytes > static_cast<std::uint64_t>(std::numeric_limits<std::int64_t>::max()))
      fail_at(0, "shape " + shape_text(h.shape) + " × itemsize " + std::to_string(h.dtype.itemsize) +
                     ": byte count overflows 64 bits");
    h.count = count;
    h.data_bytes = bytes;
    h.data_offset = base_ + s_.size();
    return h;
  }

  static std::string shape_text(const std::vector<std::int64_t>& shape) {
    std::string s = "(";
    for (std::size_t i = 0; i < shape.size(); ++i) s += (i ? ", " : "") + std::to_string(shape[i]);
    return s + (shape.size() == 1 ? ",)" : ")");
  }

 private:
  [[noreturn]] void fail_at(std::size_t at, const std::string& msg) const {
    throw ParseError(file_, 0, "byte " + std::to_string(base_ + at) + ": malformed .npy header: " + msg);
  }
  [[noreturn]] void fail(const std::string& msg) const { fail_at(i_, msg); }
  static std::string printable(std::string_view v) {
    std::string o;
    for (const char c : v.substr(0, 40)) o += (c >= 32 && c < 127) ? c : '?';
    return o;
  }
  char peek() const { return i_ < s_.size() ? s_[i_] : '\0'; }
  void ws() {
    while (i_ < s_.size() && (s_[i_] == ' ' || s_[i_] == '\t' || s_[i_] == '\n' || s_[i_] == '\r')) ++i_;
  }
  void expect(char c) {
    if (peek() != c || i_ >= s_.size()) fail(std::string("expected '") + c + "'");
    ++i_;
  }
  std::string string_literal() {
    const char q = peek();
    if (q != '\'' && q != '"') fail("expected a quoted string");
    ++i_;
    const std::size_t start = i_;
    while (i_ < s_.size() && s_[i_] != q) {
      if (s_[i_] == '\\' || s_[i_] == '\n') fail("escape sequences and newlines are not supported in strings");
      ++i_;
    }
    if (i_ >= s_.size()) fail("unterminated string");
    std::string out(s_.substr(start, i_ - start));
    ++i_;
    return out;
  }
  bool boolean() {
    if (s_.substr(i_, 4) == "True") {
      i_ += 4;
      return true;
    }
    if (s_.substr(i_, 5) == "False") {
      i_ += 5;
      return false;
    }
    fail("expected True or False");
  }
  std::int64_t integer() {
    const std::size_t start = i_;
    std::uint64_t v = 0;
    while (i_ < s_.size() && s_[i_] >= '0' && s_[i_] <= '9') {
      v = v * 10 + static_cast<std::uint64_t>(s_[i_] - '0');
      if (v > static_cast<std::uint64_t>(std::numeric_limits<std::int64_t>::max() / 16))
        fail_at(start, "dimension too large");
      ++i_;
    }
    if (i_ == start) fail("expected a non-negative integer dimension");
    if (peek() == 'L') ++i_;  // Python 2 long literals
    return static_cast<std::int64_t>(v);
  }
  std::vector<std::int64_t> tuple() {
    expect('(');
    std::vector<std::int64_t> dims;
    for (;;) {
      ws();
      if (peek() == ')') {
        ++i_;
        break;
      }
      if (dims.size() >= 32) fail("more than 32 dimensions");
      dims.push_back(integer());
      ws();
      if (peek() == ',') {
        ++i_;
        continue;
      }
      if (peek() == ')') {
        ++i_;
        if (dims.size() == 1) fail("a one-element shape tuple needs a trailing comma");
        break;
      }
      fail("expected ',' or ')' in shape");
    }
    return dims;
  }

  std::string_view s_;
  std::size_t base_;
  const std::string& file_;
  std::size_t i_ = 0;
};

/// Parses the header dict bytes (`dict` = the `pre.dict_length` bytes at `pre.dict_offset`).
inline NpyHeader npy_parse_dict(const unsigned char* dict, const NpyPreamble& pre, const std::string& file) {
  const std::string_view s(reinterpret_cast<const char*>(dict), pre.dict_length);
  if (pre.major < 3)
    for (std::size_t i = 0; i < s.size(); ++i)
      if (static_cast<unsigned char>(s[i]) >= 128)
        throw ParseError(file, 0, "byte " + std::to_string(pre.dict_offset + i) +
                                      ": malformed .npy header: non-ASCII byte in a version 1/2 header");
  return NpyDictParser(s, pre.dict_offset, file).parse();
}

/// The full header (magic, version, length, dict, padding to a multiple of 64 bytes, '\n'):
/// version 1.0 when the dict fits 65535 bytes, else 2.0.
inline std::string npy_make_header(const NpyDType& dtype, bool fortran_order, const std::vector<std::int64_t>& shape) {
  std::string dict = "{'descr': '" + dtype.descr() + "', 'fortran_order': " + (fortran_order ? "True" : "False") +
                     ", 'shape': " + NpyDictParser::shape_text(shape) + ", }";
  const bool v2 = dict.size() + 1 + 10 > 65535;
  const std::size_t pre = v2 ? 12 : 10;
  const std::size_t total = (pre + dict.size() + 1 + 63) / 64 * 64;
  dict.append(total - pre - dict.size() - 1, ' ');
  dict += '\n';
  std::string h(npy_magic, 6);
  h += static_cast<char>(v2 ? 2 : 1);
  h += '\0';
  const std::uint64_t len = dict.size();
  h += static_cast<char>(len & 0xff);
  h += static_cast<char>((len >> 8) & 0xff);
  if (v2) {
    h += static_cast<char>((len >> 16) & 0xff);
    h += static_cast<char>((len >> 24) & 0xff);
  }
  return h + dict;
}

}  // namespace detail
}  // namespace simsr::io
