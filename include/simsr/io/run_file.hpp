#pragma once
/// \file
/// The files of a resumable run (datagen): each carries the fingerprint of the run that wrote it
/// (core/fingerprint.hpp), so a file of another run is refused or recomputed, never continued;
/// and named arrays are read back checked, the file named in every error.
///
///     io::set_fingerprint(z, print);  io::write_npz(file, z);
///     if (io::fingerprint_of(io::read_npz(file)) == print) ...   // this run's: reuse

#include <string>
#include <vector>

#include "../core/error.hpp"
#include "../core/types.hpp"
#include "npz.hpp"

namespace simsr::io {

namespace detail {
/// A fingerprint array's string ("" for an empty one).
inline std::string fingerprint_string(const NpyArray& a) {
  const auto s = a.to_strings();
  return s.empty() ? "" : s[0];
}
}  // namespace detail

/// The fingerprint a run file carries ("" for none). A file may carry more than one, each under
/// its own array name (a cloth sequence: "fine_fingerprint", its fine cloth's simulation alone).
inline std::string fingerprint_of(const NpzArrays& z, const std::string& name = "fingerprint") {
  return z.contains(name) ? detail::fingerprint_string(z.at(name)) : "";
}

/// The same, read from an open archive without reading its other members.
inline std::string fingerprint_of(NpzReader& z, const std::string& name = "fingerprint") {
  return z.contains(name) ? detail::fingerprint_string(z.read(name)) : "";
}

/// `print` as the file's fingerprint array (`name`: see fingerprint_of).
inline void set_fingerprint(NpzArrays& z, const std::string& print, const std::string& name = "fingerprint") {
  z[name] = make_npy(std::vector<std::string>{print});
}

/// A rows×3 array `name` of a run file; ArgumentError naming the file when it is missing,
/// ShapeError when it has another shape.
inline Points<> points_of(const NpzArrays& z, const std::string& name, Index rows, const std::string& file) {
  if (!z.contains(name)) throw ArgumentError(file + ": no '" + name + "' array");
  const auto& a = z.at(name);
  if (a.ndim() != 2 || a.shape[0] != rows || a.shape[1] != 3)
    throw ShapeError(file + ": " + name, {rows, 3}, {a.ndim() > 0 ? Index(a.shape[0]) : 0, a.ndim() > 1 ? Index(a.shape[1]) : 0});
  return a.to_points<double>();
}

/// A scalar `name` of a run file; ArgumentError naming the file when it is missing or not a scalar.
inline double scalar_of(const NpzArrays& z, const std::string& name, const std::string& file) {
  if (!z.contains(name)) throw ArgumentError(file + ": no '" + name + "' array");
  const auto& a = z.at(name);
  if (a.ndim() != 0) throw ArgumentError(file + ": '" + name + "' is not a scalar");
  return a.item<double>();
}

}  // namespace simsr::io
