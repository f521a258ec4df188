#pragma once
/// \file
/// A surface's contact patches as a file (`simsr datagen --scenario face` writes the lips as
/// DIR/hr_lips.npz): `a` and `b`, T×3 int32 triangles of the HR surface (rows of hr_rest.obj's
/// faces). The training loss's contact term (nn/contact_loss.hpp) and the evaluation's
/// intersection count read it.
///
///     data::write_contact_patches("hr_lips.npz", lips);
///     ContactPatches lips = data::read_contact_patches("hr_lips.npz", problem.num_hr());

#include <cstdint>
#include <filesystem>
#include <string>

#include "../core/error.hpp"
#include "../io/npz.hpp"
#include "../mesh/contact_patches.hpp"

namespace simsr::data {

/// Writes `patches` (checked first: ArgumentError as ContactPatches::check) atomically.
inline void write_contact_patches(const std::filesystem::path& file, const ContactPatches& patches, Index num_vertices) {
  patches.check(num_vertices, file.string());
  io::NpzArrays z;
  z["a"] = io::make_npy(patches.a);
  z["b"] = io::make_npy(patches.b);
  io::write_npz(file, z);
}

/// Reads what write_contact_patches wrote, checked against the surface's vertex count: a missing
/// array or one that is not T×3 is a ShapeError/ArgumentError naming the file and the array.
inline ContactPatches read_contact_patches(const std::filesystem::path& file, Index num_vertices) {
  const io::NpzArrays z = io::read_npz(file);
  ContactPatches p;
  for (const char* name : {"a", "b"}) {
    if (!z.contains(name)) throw ArgumentError(file.string() + ": no array '" + name + "' (a contact patches file has 'a' and 'b')");
    const io::NpyArray& arr = z.at(name);
    if (arr.ndim() != 2 || arr.shape[1] != 3)
      throw ShapeError(file.string() + ": " + name + " (triangles)", {-1, 3}, {arr.ndim() > 0 ? Index(arr.shape[0]) : 0, arr.ndim() > 1 ? Index(arr.shape[1]) : 0});
    (std::string(name) == "a" ? p.a : p.b) = arr.to_matrix<VIndex>();
  }
  p.check(num_vertices, file.string());
  return p;
}

}  // namespace simsr::data
