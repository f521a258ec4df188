#pragma once
/// \file
/// NumPy `.npy` arrays: read (format versions 1.0, 2.0, 3.0) and write (1.0, or 2.0 for huge
/// headers), C and Fortran order, 0-d and empty arrays, dtypes bool, int8..int64, uint8..uint64,
/// float32/64 in either byte order and unicode `U{n}`.
///
///     auto a = simsr::io::read_npy("geo_dist_tet2tet_idx.npy");       // 1747×100 int64
///     xt::xtensor<int, 2> idx = a.to_xtensor<int, 2>();             // checked: throws if a value overflows int
///     simsr::io::write_npy("err.npy", Eigen::VectorXd(...));          // shape (n,)
///
/// The reader is hardened for hostile input: the header is parsed by a small validating parser, and
/// the byte count a header announces is checked against the bytes actually available before any
/// allocation. Every failure is a simsr::ParseError(file, 0, "byte <offset>: ...").

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <memory>
#include <span>
#include <string>
#include <type_traits>
#include <vector>

#include <Eigen/Core>
#include <xtensor/xarray.hpp>
#include <xtensor/xtensor.hpp>

#include "../core/error.hpp"
#include "../core/types.hpp"
#include "atomic_file.hpp"
#include "detail/npy_convert.hpp"
#include "detail/npy_header.hpp"

namespace simsr::io {

/// A dynamically typed n-d array as stored in a .npy file: `bytes` holds product(shape) × itemsize
/// bytes in the file's byte order and memory order (C or Fortran). Typed accessors convert to the
/// requested element type in C (row-major) order and throw ArgumentError when a value would change
/// (float → integer, integers out of range, integers a float cannot represent exactly, bool from
/// values other than 0/1); float64 → float32 rounds to nearest (only overflow to ±inf throws).
struct NpyArray {
  NpyDType dtype;
  std::vector<std::int64_t> shape;  ///< empty for 0-d arrays
  bool fortran_order = false;
  std::vector<std::byte> bytes;
  std::string source = "<npy>";  ///< file (or archive member) it came from, used in messages

  std::size_t ndim() const { return shape.size(); }
  /// Number of elements (1 for 0-d). Throws ArgumentError when it overflows.
  std::int64_t size() const {
    std::uint64_t n = 1;
    for (const auto d : shape)
      if (d < 0 || __builtin_mul_overflow(n, static_cast<std::uint64_t>(d), &n) ||
          n > static_cast<std::uint64_t>(INT64_MAX))
        throw ArgumentError(source + ": invalid shape " + detail::NpyDictParser::shape_text(shape));
    return static_cast<std::int64_t>(n);
  }
  bool is_numeric() const { return dtype.kind != NpyKind::Unicode; }

  /// Throws ArgumentError unless bytes.size() == size() × itemsize.
  void validate() const {
    const auto n = static_cast<std::uint64_t>(size());
    std::uint64_t b = 0;
    if (__builtin_mul_overflow(n, static_cast<std::uint64_t>(dtype.itemsize), &b) || b != bytes.size())
      throw ArgumentError(source + ": " + std::to_string(bytes.size()) + " data bytes do not match shape " +
                          detail::NpyDictParser::shape_text(shape) + " of " + dtype.name());
  }

  /// All elements, flattened in C order.
  template <class T>
  std::vector<T> to_vector() const {
    validate();
    const auto n = static_cast<std::size_t>(size());
    if constexpr (std::is_same_v<T, bool>) {
      const auto tmp = std::make_unique<bool[]>(n);
      gather_c_order(tmp.get());
      return std::vector<bool>(tmp.get(), tmp.get() + n);
    } else {
      std::vector<T> out(n);
      gather_c_order(out.data());
      return out;
    }
  }

  /// The array as an xt::xarray<T> (row-major) of the same shape.
  template <class T>
  xt::xarray<T> to_xarray() const {
    validate();
    std::vector<std::size_t> s(shape.begin(), shape.end());
    xt::xarray<T> a = xt::xarray<T>::from_shape(s);
    gather_c_order(a.data());
    return a;
  }

  /// The array as an xt::xtensor<T, N>; ShapeError unless ndim() == N.
  template <class T, std::size_t N>
  xt::xtensor<T, N> to_xtensor() const {
    if (ndim() != N) throw ShapeError(source, std::vector<std::int64_t>(N, -1), shape);
    validate();
    std::array<std::size_t, N> s{};
    for (std::size_t i = 0; i < N; ++i) s[i] = static_cast<std::size_t>(shape[i]);
    xt::xtensor<T, N> a = xt::xtensor<T, N>::from_shape(s);
    gather_c_order(a.data());
    return a;
  }

  /// A 2-d array (r, c) as an r×c row-major matrix; 1-d (n,) gives n×1, 0-d gives 1×1.
  template <class T>
  Eigen::Matrix<T, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> to_matrix() const {
    if (ndim() > 2) throw ShapeError(source, {-1, -1}, shape);
    validate();
    const Index r = ndim() >= 1 ? shape[0] : 1, c = ndim() == 2 ? shape[1] : 1;
    Eigen::Matrix<T, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> m(r, c);
    gather_c_order(m.data());
    return m;
  }

  /// An N×3 array as #V×3 points.
  template <class S = Scalar>
  Points<S> to_points() const {
    if (ndim() != 2 || shape[1] != 3) throw ShapeError(source, {-1, 3}, shape);
    validate();
    Points<S> p(shape[0], 3);
    gather_c_order(p.data());
    return p;
  }

  /// Number of frames of an F×N×3 array (shape[0]).
  Index num_frames() const {
    if (ndim() != 3 || shape[2] != 3) throw ShapeError(source, {-1, -1, 3}, shape);
    return shape[0];
  }

  /// Frame f of an F×N×3 array as #V×3 points (only that frame is converted).
  template <class S = Scalar>
  Points<S> frame_points(Index f) const {
    const Index frames = num_frames();
    if (f < 0 || f >= frames)
      throw ArgumentError(source + ": frame " + std::to_string(f) + " out of range [0, " + std::to_string(frames) + ")");
    validate();
    const std::int64_t n = shape[1];
    const std::int64_t s0 = fortran_order ? 1 : n * 3, s1 = fortran_order ? shape[0] : 3,
                       s2 = fortran_order ? shape[0] * n : 1;
    Points<S> p(n, 3);
    gather(p.data(), n * 3, [&](std::int64_t k) { return f * s0 + (k / 3) * s1 + (k % 3) * s2; });
    return p;
  }

  /// The single element of a 0-d (or one-element) array.
  template <class T>
  T item() const {
    if (size() != 1) throw ShapeError(source + " (item)", {}, shape);
    validate();
    T v{};
    gather(&v, 1, [](std::int64_t) { return std::int64_t{0}; });
    return v;
  }

  /// A unicode array's strings (UTF-8, trailing NULs stripped as numpy does), flattened in C order.
  std::vector<std::string> to_strings() const {
    if (dtype.kind != NpyKind::Unicode)
      throw ArgumentError(source + ": dtype " + dtype.name() + " is not a unicode string dtype");
    validate();
    const std::int64_t n = size();
    const std::size_t chars = dtype.itemsize / 4;
    const bool swap = dtype.needs_swap();
    std::vector<std::string> out(static_cast<std::size_t>(n));
    for (std::int64_t k = 0; k < n; ++k) {
      const std::byte* e = bytes.data() + static_cast<std::size_t>(storage_index(k)) * dtype.itemsize;
      std::size_t len = chars;
      auto cp_at = [&](std::size_t i) {
        std::uint32_t cp;
        std::memcpy(&cp, e + 4 * i, 4);
        return swap ? detail::npy_byteswap(cp) : cp;
      };
      while (len > 0 && cp_at(len - 1) == 0) --len;
      std::string& s = out[static_cast<std::size_t>(k)];
      for (std::size_t i = 0; i < len; ++i)
        if (!detail::utf8_append(s, cp_at(i)))
          throw ParseError(source, 0, "string element " + std::to_string(k) + " holds invalid code point " +
                                          std::to_string(cp_at(i)));
    }
    return out;
  }

 private:
  /// Storage (memory-order) index of the element with C-order index k.
  std::int64_t storage_index(std::int64_t k) const {
    if (!fortran_order || ndim() < 2) return k;
    std::int64_t idx = 0, stride = 1;
    std::vector<std::int64_t> fs(ndim());
    for (std::size_t d = 0; d < ndim(); ++d) {
      fs[d] = stride;
      stride *= shape[d];
    }
    for (std::size_t d = ndim(); d-- > 0;) {
      idx += (k % shape[d]) * fs[d];
      k /= shape[d];
    }
    return idx;
  }

  template <class T>
  void gather_c_order(T* out) const {
    const std::int64_t n = size();
    if (!fortran_order || ndim() < 2) {
      gather(out, n, [](std::int64_t k) { return k; });
      return;
    }
    std::vector<std::int64_t> fs(ndim());
    std::int64_t stride = 1;
    for (std::size_t d = 0; d < ndim(); ++d) {
      fs[d] = stride;
      stride *= shape[d];
    }
    // Odometer over C order, tracking the Fortran storage index incrementally.
    std::vector<std::int64_t> i(ndim(), 0);
    std::int64_t idx = 0;
    std::vector<std::int64_t> order;
    order.reserve(static_cast<std::size_t>(n));
    for (std::int64_t k = 0; k < n; ++k) {
      order.push_back(idx);
      for (std::size_t d = ndim(); d-- > 0;) {
        ++i[d];
        idx += fs[d];
        if (i[d] < shape[d]) break;
        idx -= fs[d] * shape[d];
        i[d] = 0;
      }
    }
    gather(out, n, [&](std::int64_t k) { return order[static_cast<std::size_t>(k)]; });
  }

  template <class T, class StorageIndex>
  void gather(T* out, std::int64_t n, StorageIndex idx) const {
    static_assert(std::is_arithmetic_v<T>, "npy: target element type must be bool, an integer or a float");
    detail::npy_visit_numeric(dtype, source, [&](auto tag) {
      using Src = decltype(tag);
      const bool swap = dtype.needs_swap();
      const std::byte* base = bytes.data();
      for (std::int64_t k = 0; k < n; ++k) {
        const std::byte* e = base + static_cast<std::size_t>(idx(k)) * sizeof(Src);
        Src v;
        if constexpr (std::is_same_v<Src, bool>) {
          v = std::to_integer<unsigned char>(*e) != 0;
        } else {
          std::memcpy(&v, e, sizeof(Src));
          if (swap) v = detail::npy_byteswap(v);
        }
        if (!detail::npy_checked_cast(v, out[k])) {
          std::string value;
          if constexpr (std::is_same_v<Src, bool>)
            value = v ? "True" : "False";
          else
            value = std::to_string(v);
          throw ArgumentError(source + ": element " + std::to_string(k) + " (" + value + ") of dtype " +
                              dtype.name() + " cannot be converted to " + detail::npy_type_name<T>() +
                              " without loss");
        }
      }
      return 0;
    });
  }
};

namespace detail {

/// Reads a .npy from a byte stream holding exactly `available` bytes. `read(dst, n)` copies up to
/// n bytes and returns how many it copied (fewer only at the end of the stream); it may throw.
template <class Read>
NpyArray npy_read_stream(Read&& read, std::uint64_t available, const std::string& file) {
  unsigned char pre_bytes[12] = {};
  const std::size_t pre_n = static_cast<std::size_t>(std::min<std::uint64_t>(12, available));
  if (read(pre_bytes, pre_n) != pre_n) throw ParseError(file, 0, "byte 0: stream ended inside the preamble");
  const NpyPreamble pre = npy_parse_preamble(pre_bytes, pre_n, available, file);
  std::vector<unsigned char> dict(pre.dict_length);
  const std::size_t have = std::min(pre_n - pre.dict_offset, pre.dict_length);
  if (have) std::memcpy(dict.data(), pre_bytes + pre.dict_offset, have);
  if (read(dict.data() + have, pre.dict_length - have) != pre.dict_length - have)
    throw ParseError(file, 0, "byte " + std::to_string(pre.dict_offset + have) + ": stream ended inside the header");
  const NpyHeader h = npy_parse_dict(dict.data(), pre, file);
  // Data bytes for a v1 header whose dict is shorter than the 2 bytes of prefix overlap cannot be
  // negative: pre_n is at most 12 and data_offset at least 10.
  std::uint64_t consumed = std::max<std::uint64_t>(pre_n, h.data_offset);
  const std::uint64_t left = available - h.data_offset;
  if (h.data_bytes > left)
    throw ParseError(file, 0, "byte " + std::to_string(h.data_offset) + ": truncated data: shape " +
                                  NpyDictParser::shape_text(h.shape) + " of " + h.dtype.name() + " needs " +
                                  std::to_string(h.data_bytes) + " bytes, " + std::to_string(left) + " available");
  if (h.data_bytes < left)
    throw ParseError(file, 0, "byte " + std::to_string(h.data_offset + h.data_bytes) + ": " +
                                  std::to_string(left - h.data_bytes) + " trailing bytes after the array data");
  NpyArray a;
  a.dtype = h.dtype;
  a.shape = h.shape;
  a.fortran_order = h.fortran_order;
  a.source = file;
  a.bytes.resize(static_cast<std::size_t>(h.data_bytes));
  // The preamble read may already hold the first data bytes (tiny v1 headers).
  std::size_t pre_data = pre_n > h.data_offset ? pre_n - h.data_offset : 0;
  pre_data = std::min<std::size_t>(pre_data, a.bytes.size());
  if (pre_data) std::memcpy(a.bytes.data(), pre_bytes + h.data_offset, pre_data);
  const std::size_t rest = a.bytes.size() - pre_data;
  if (rest && read(a.bytes.data() + pre_data, rest) != rest)
    throw ParseError(file, 0, "byte " + std::to_string(consumed) + ": stream ended inside the array data");
  return a;
}

}  // namespace detail

/// Parses a .npy held in memory. `source` names it in error messages.
inline NpyArray read_npy_buffer(const void* data, std::size_t size, const std::string& source = "<memory>") {
  const auto* p = static_cast<const unsigned char*>(data);
  std::size_t pos = 0;
  auto read = [&](void* dst, std::size_t n) {
    const std::size_t k = std::min(n, size - pos);
    if (k) std::memcpy(dst, p + pos, k);
    pos += k;
    return k;
  };
  return detail::npy_read_stream(read, size, source);
}

inline NpyArray read_npy_buffer(std::span<const std::byte> data, const std::string& source = "<memory>") {
  return read_npy_buffer(data.data(), data.size(), source);
}

/// Reads a .npy file; only the header and then exactly the announced data are read.
inline NpyArray read_npy(const std::filesystem::path& path) {
  const std::string name = path.string();
  std::ifstream in(path, std::ios::binary);
  if (!in) throw ParseError(name, 0, "cannot open file");
  in.seekg(0, std::ios::end);
  const auto end = in.tellg();
  if (end < 0) throw ParseError(name, 0, "cannot determine the file size");
  in.seekg(0, std::ios::beg);
  auto read = [&](void* dst, std::size_t n) {
    in.read(static_cast<char*>(dst), static_cast<std::streamsize>(n));
    return static_cast<std::size_t>(in.gcount());
  };
  return detail::npy_read_stream(read, static_cast<std::uint64_t>(end), name);
}

/// Serializes an array to .npy bytes (version 1.0 header unless it needs 2.0).
inline std::vector<std::byte> npy_bytes(const NpyArray& a) {
  a.validate();
  const std::string h = detail::npy_make_header(a.dtype, a.fortran_order, a.shape);
  std::vector<std::byte> out(h.size() + a.bytes.size());
  std::memcpy(out.data(), h.data(), h.size());
  if (!a.bytes.empty()) std::memcpy(out.data() + h.size(), a.bytes.data(), a.bytes.size());
  return out;
}

/// Writes an array to a .npy file (dtype, byte order and memory order as stored in `a`), atomically
/// (io/atomic_file.hpp): WriteError when it cannot be written, the previous file then unchanged.
inline void write_npy(const std::filesystem::path& path, const NpyArray& a) {
  a.validate();
  const std::string h = detail::npy_make_header(a.dtype, a.fortran_order, a.shape);
  AtomicFile out(path);
  out.write(h);
  out.write(a.bytes);
  out.commit();
}

/// An array of the given shape from `product(shape)` elements at `data`, in C order (or Fortran
/// order when `fortran_order`); T is bool, an integer of up to 64 bits, float or double.
template <class T>
NpyArray make_npy(std::vector<std::int64_t> shape, const T* data, bool fortran_order = false) {
  NpyArray a;
  a.dtype = NpyDType::of<T>();
  a.shape = std::move(shape);
  a.fortran_order = fortran_order;
  const auto n = static_cast<std::size_t>(a.size());
  a.bytes.resize(n * sizeof(T));
  if (n) std::memcpy(a.bytes.data(), data, n * sizeof(T));
  return a;
}

/// An array from an xtensor expression (evaluated, written in C order, same shape and value type).
template <class E>
NpyArray make_npy(const xt::xexpression<E>& e) {
  using T = typename E::value_type;
  const xt::xarray<T, xt::layout_type::row_major> tmp = e.derived_cast();
  return make_npy<T>(std::vector<std::int64_t>(tmp.shape().begin(), tmp.shape().end()), tmp.data());
}

/// An array from an Eigen matrix, written in C (row-major) order: shape (rows, cols), or (rows,)
/// for compile-time column vectors such as Eigen::VectorXd.
template <class D>
NpyArray make_npy(const Eigen::DenseBase<D>& m) {
  using T = typename D::Scalar;
  const Eigen::Matrix<T, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> tmp = m.derived();
  if constexpr (D::ColsAtCompileTime == 1)
    return make_npy<T>({static_cast<std::int64_t>(tmp.rows())}, tmp.data());
  else
    return make_npy<T>({static_cast<std::int64_t>(tmp.rows()), static_cast<std::int64_t>(tmp.cols())}, tmp.data());
}

/// A 1-d unicode array `<U{n}` (n = longest string in code points, at least 1) from UTF-8 strings;
/// ArgumentError on invalid UTF-8 or embedded trailing NULs (numpy would strip them).
inline NpyArray make_npy(const std::vector<std::string>& strings) {
  std::vector<std::u32string> cps;
  cps.reserve(strings.size());
  std::size_t width = 1;
  for (const auto& s : strings) {
    cps.push_back(detail::utf8_decode(s));
    if (!cps.back().empty() && cps.back().back() == 0)
      throw ArgumentError("npy: string '" + s + "' ends in NUL, which numpy strips");
    width = std::max(width, cps.back().size());
  }
  NpyArray a;
  a.dtype.kind = NpyKind::Unicode;
  a.dtype.itemsize = 4 * width;
  a.dtype.big_endian = std::endian::native == std::endian::big;
  a.shape = {static_cast<std::int64_t>(strings.size())};
  a.bytes.assign(strings.size() * a.dtype.itemsize, std::byte{0});
  for (std::size_t i = 0; i < cps.size(); ++i)
    for (std::size_t j = 0; j < cps[i].size(); ++j) {
      const auto cp = static_cast<std::uint32_t>(cps[i][j]);
      std::memcpy(a.bytes.data() + i * a.dtype.itemsize + 4 * j, &cp, 4);
    }
  return a;
}

/// Stacks F frames of #V×3 points (all the same #V) into one F×V×3 array.
template <class S>
NpyArray make_npy_frames(const std::vector<Points<S>>& frames) {
  const std::int64_t v = frames.empty() ? 0 : frames.front().rows();
  std::vector<S> data;
  data.reserve(frames.size() * static_cast<std::size_t>(v) * 3);
  for (std::size_t f = 0; f < frames.size(); ++f) {
    if (frames[f].rows() != v) throw ShapeError("npy frame " + std::to_string(f), {v, 3}, {frames[f].rows(), 3});
    data.insert(data.end(), frames[f].data(), frames[f].data() + frames[f].size());
  }
  return make_npy<S>({static_cast<std::int64_t>(frames.size()), v, 3}, data.data());
}

/// Writes anything make_npy accepts (xtensor expression, Eigen matrix, strings).
template <class X>
void write_npy(const std::filesystem::path& path, const X& x) {
  write_npy(path, make_npy(x));
}

}  // namespace simsr::io
