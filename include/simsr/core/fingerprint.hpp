#pragma once
/// \file
/// A 64-bit FNV-1a fingerprint of arrays, to tell whether a file was written from the same data
/// as the run that reads it (a training checkpoint and its frames): not a cryptographic hash, a
/// cheap and platform-independent "same bytes?" check.
///
///     Fingerprint f;
///     f.add(frames.ldx).add(frames.hdx).add(std::int64_t(frames.frames));
///     std::string text = f.hex();   // "9f0c…", 16 hexadecimal digits

#include <cstdint>
#include <cstdio>
#include <string>
#include <type_traits>
#include <vector>

#include <Eigen/Core>

namespace simsr {

/// FNV-1a over everything added, in order (shapes are part of what `add(matrix)` adds).
class Fingerprint {
 public:
  Fingerprint& add_bytes(const void* data, std::size_t size) {
    const auto* p = static_cast<const unsigned char*>(data);
    for (std::size_t i = 0; i < size; ++i) {
      h_ ^= p[i];
      h_ *= 1099511628211ULL;
    }
    return *this;
  }
  template <class T>
    requires std::is_arithmetic_v<T>
  Fingerprint& add(T value) {
    return add_bytes(&value, sizeof value);
  }
  /// The shape, then every entry in row-major order (the same fingerprint for either storage order).
  template <class D>
  Fingerprint& add(const Eigen::DenseBase<D>& m) {
    add(std::int64_t(m.rows())).add(std::int64_t(m.cols()));
    for (Eigen::Index r = 0; r < m.rows(); ++r)
      for (Eigen::Index c = 0; c < m.cols(); ++c) add(typename D::Scalar(m(r, c)));
    return *this;
  }
  template <class T>
  Fingerprint& add(const std::vector<T>& v) {
    add(std::int64_t(v.size()));
    for (const T& x : v) add(x);
    return *this;
  }

  std::uint64_t value() const { return h_; }
  std::string hex() const {
    char buf[17];
    std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(h_));
    return buf;
  }

 private:
  std::uint64_t h_ = 14695981039346656037ULL;
};

}  // namespace simsr
