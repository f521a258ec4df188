#pragma once
/// \file
/// Element conversions for NpyArray: checked numeric casts (lossy ones throw), byte swapping,
/// dtype dispatch, and UCS-4 ⇄ UTF-8 for numpy's `U{n}` strings.

#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <string>
#include <type_traits>
#include <utility>

#include "../../core/error.hpp"
#include "npy_header.hpp"

namespace simsr::io::detail {

template <class T>
T npy_byteswap(T v) {
  unsigned char b[sizeof(T)];
  std::memcpy(b, &v, sizeof(T));
  for (std::size_t i = 0; i < sizeof(T) / 2; ++i) std::swap(b[i], b[sizeof(T) - 1 - i]);
  std::memcpy(&v, b, sizeof(T));
  return v;
}

/// Calls f(Src{}) with Src the C++ type of a numeric dtype; throws for unicode.
template <class F>
decltype(auto) npy_visit_numeric(const NpyDType& t, const std::string& what, F&& f) {
  switch (t.kind) {
    case NpyKind::Bool: return f(bool{});
    case NpyKind::Int:
      switch (t.itemsize) {
        case 1: return f(std::int8_t{});
        case 2: return f(std::int16_t{});
        case 4: return f(std::int32_t{});
        default: return f(std::int64_t{});
      }
    case NpyKind::UInt:
      switch (t.itemsize) {
        case 1: return f(std::uint8_t{});
        case 2: return f(std::uint16_t{});
        case 4: return f(std::uint32_t{});
        default: return f(std::uint64_t{});
      }
    case NpyKind::Float:
      if (t.itemsize == 4) return f(float{});
      return f(double{});
    case NpyKind::Unicode: break;
  }
  throw ArgumentError(what + ": dtype " + t.name() + " is not numeric");
}

/// Type name of a C++ element type, for messages.
template <class T>
std::string npy_type_name() {
  return NpyDType::of<T>().name();
}

/// Converts v to T; returns false when the value would change (float to integer, integers out of
/// range, integers a float cannot hold exactly, finite float64 overflowing float32, non-0/1 to bool).
template <class T, class Src>
bool npy_checked_cast(Src v, T& out) {
  if constexpr (std::is_same_v<T, bool>) {
    if constexpr (std::is_same_v<Src, bool>) {
      out = v;
      return true;
    } else if constexpr (std::is_integral_v<Src>) {
      if (v != 0 && v != 1) return false;
      out = v != 0;
      return true;
    } else {
      return false;
    }
  } else if constexpr (std::is_integral_v<T>) {
    if constexpr (std::is_same_v<Src, bool>) {
      out = static_cast<T>(v);
      return true;
    } else if constexpr (std::is_integral_v<Src>) {
      if (!std::in_range<T>(v)) return false;
      out = static_cast<T>(v);
      return true;
    } else {
      return false;
    }
  } else {
    static_assert(std::is_floating_point_v<T>);
    if constexpr (std::is_same_v<Src, bool>) {
      out = v ? T(1) : T(0);
      return true;
    } else if constexpr (std::is_integral_v<Src>) {
      const T t = static_cast<T>(v);
      if constexpr (std::numeric_limits<Src>::digits > std::numeric_limits<T>::digits) {
        // Round-trip check; 2^63 / 2^64 (the rounding of the largest values) is out of Src's range.
        const T lim = std::ldexp(T(1), std::numeric_limits<Src>::digits);
        if (!(t < lim) || !(t >= -lim) || static_cast<Src>(t) != v) return false;
      }
      out = t;
      return true;
    } else {
      const T t = static_cast<T>(v);
      if constexpr (sizeof(T) < sizeof(Src))
        if (std::isinf(t) && !std::isinf(v)) return false;
      out = t;
      return true;
    }
  }
}

/// Appends code point cp as UTF-8; false when cp is not a Unicode scalar value.
inline bool utf8_append(std::string& s, std::uint32_t cp) {
  if (cp > 0x10FFFF || (cp >= 0xD800 && cp <= 0xDFFF)) return false;
  if (cp < 0x80) {
    s += static_cast<char>(cp);
  } else if (cp < 0x800) {
    s += static_cast<char>(0xC0 | (cp >> 6));
    s += static_cast<char>(0x80 | (cp & 0x3F));
  } else if (cp < 0x10000) {
    s += static_cast<char>(0xE0 | (cp >> 12));
    s += static_cast<char>(0x80 | ((cp >> 6) & 0x3F));
    s += static_cast<char>(0x80 | (cp & 0x3F));
  } else {
    s += static_cast<char>(0xF0 | (cp >> 18));
    s += static_cast<char>(0x80 | ((cp >> 12) & 0x3F));
    s += static_cast<char>(0x80 | ((cp >> 6) & 0x3F));
    s += static_cast<char>(0x80 | (cp & 0x3F));
  }
  return true;
}

/// Decodes UTF-8 into code points; throws ArgumentError on invalid sequences.
inline std::u32string utf8_decode(const std::string& s) {
  std::u32string out;
  std::size_t i = 0;
  auto bad = [&] { throw ArgumentError("npy: string is not valid UTF-8 at byte " + std::to_string(i)); };
  while (i < s.size()) {
    const auto c = static_cast<unsigned char>(s[i]);
    std::uint32_t cp = 0;
    int extra = 0;
    if (c < 0x80) {
      cp = c;
      extra = 0;
    } else if ((c & 0xE0) == 0xC0) {
      cp = c & 0x1F;
      extra = 1;
    } else if ((c & 0xF0) == 0xE0) {
      cp = c & 0x0F;
      extra = 2;
    } else if ((c & 0xF8) == 0xF0) {
      cp = c & 0x07;
      extra = 3;
    } else {
      bad();
    }
    if (extra > 0 && i + static_cast<std::size_t>(extra) >= s.size()) bad();
    for (int k = 1; k <= extra; ++k) {
      const auto cc = static_cast<unsigned char>(s[i + static_cast<std::size_t>(k)]);
      if ((cc & 0xC0) != 0x80) bad();
      cp = cp << 6 | (cc & 0x3F);
    }
    static constexpr std::uint32_t min_cp[4] = {0, 0x80, 0x800, 0x10000};
    if (cp < min_cp[extra] || cp > 0x10FFFF || (cp >= 0xD800 && cp <= 0xDFFF)) bad();
    out += static_cast<char32_t>(cp);
    i += static_cast<std::size_t>(extra) + 1;
  }
  return out;
}

}  // namespace simsr::io::detail
