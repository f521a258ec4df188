#pragma once
/// \file
/// VTK XML UnstructuredGrid (.vtu) writer for ParaView, and .pvd time series of .vtu frames.
///
///     simsr::io::VtuGrid g(mesh);                       // TetMesh or TriMesh, or set_points/set_tets/...
///     g.add_point_data("error", err);                   // #V values (or #V×3 vectors)
///     g.add_cell_data("volume", vol);                   // one row per cell: tets first, then triangles
///     simsr::io::write_vtu("frame.vtu", g);             // binary: base64 inline
///
///     simsr::io::PvdWriter series("heatmap.pvd");       // frames go to heatmap/heatmap_000000.vtu, ...
///     for (int f = 0; f < F; ++f) series.add(f, grid_of_frame(f));
///
/// Binary mode writes each DataArray as `format="binary"` inline base64, uncompressed, with a UInt64
/// byte-count header encoded separately from the data (the layout VTK's own writer uses); it keeps
/// the file self-contained and valid XML, at 4/3 the raw size. ASCII mode prints values with
/// max_digits10 digits, so it round-trips exactly too. Points are Float64 or Float32 (the scalar type
/// given), connectivity and offsets Int32 (Int64 past 2^31 points or indices), cell types UInt8 (VTK_TETRA 10, VTK_TRIANGLE 5).

#include <array>
#include <bit>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <locale>
#include <sstream>
#include <string>
#include <type_traits>
#include <utility>
#include <variant>
#include <vector>

#include <Eigen/Core>

#include "../core/error.hpp"
#include "../core/types.hpp"
#include "../mesh/tet_mesh.hpp"
#include "../mesh/tri_mesh.hpp"
#include "atomic_file.hpp"
#include "detail/base64.hpp"

namespace simsr::io {

/// ASCII or binary (inline base64) DataArrays.
enum class VtuFormat { Ascii, Binary };

/// VTK cell type codes written by VtuGrid.
inline constexpr std::uint8_t vtk_triangle = 5;
inline constexpr std::uint8_t vtk_tetra = 10;

/// A named data array of `tuples()` tuples with `components` values each, tuple-major; the
/// element type (Float64, Float32, Int32, Int64) is that of the vector held.
struct VtuArray {
  using Values = std::variant<std::vector<double>, std::vector<float>, std::vector<std::int32_t>, std::vector<std::int64_t>>;
  std::string name;
  int components = 1;
  Values values;

  Index tuples() const {
    return std::visit([&](const auto& v) { return static_cast<Index>(v.size()) / components; }, values);
  }
};

namespace detail {

template <class T>
constexpr const char* vtu_type_name() {
  if constexpr (std::is_same_v<T, double>) return "Float64";
  if constexpr (std::is_same_v<T, float>) return "Float32";
  if constexpr (std::is_same_v<T, std::int32_t>) return "Int32";
  if constexpr (std::is_same_v<T, std::int64_t>) return "Int64";
  if constexpr (std::is_same_v<T, std::uint8_t>) return "UInt8";
}

/// The storage type of element type T: floats and doubles stay, integers of up to 32 bits become
/// Int32, wider ones Int64.
template <class T>
using vtu_storage_t =
    std::conditional_t<std::is_same_v<T, float>, float,
                       std::conditional_t<std::is_floating_point_v<T>, double,
                                          std::conditional_t<(sizeof(T) <= 4 && !(std::is_unsigned_v<T> && sizeof(T) == 4)),
                                                             std::int32_t, std::int64_t>>>;

inline std::string vtu_xml_escape(const std::string& s) {
  std::string o;
  for (const char c : s) {
    switch (c) {
      case '&': o += "&amp;"; break;
      case '<': o += "&lt;"; break;
      case '>': o += "&gt;"; break;
      case '"': o += "&quot;"; break;
      case '\'': o += "&apos;"; break;
      default:
        if (static_cast<unsigned char>(c) < 0x20 && c != '\t') throw ArgumentError("vtu: control character in array name");
        o += c;
    }
  }
  return o;
}

template <class T>
void vtu_data_array(std::ostream& out, const std::string& name, int components, const std::vector<T>& v, VtuFormat fmt) {
  out << "        <DataArray type=\"" << vtu_type_name<T>() << '"';
  if (!name.empty()) out << " Name=\"" << vtu_xml_escape(name) << '"';
  if (components != 1) out << " NumberOfComponents=\"" << components << '"';
  out << " format=\"" << (fmt == VtuFormat::Ascii ? "ascii" : "binary") << "\">\n";
  if (fmt == VtuFormat::Binary) {
    const std::uint64_t nbytes = v.size() * sizeof(T);
    std::string s = "          ";
    base64_append(s, &nbytes, sizeof(nbytes));
    base64_append(s, v.data(), static_cast<std::size_t>(nbytes));
    out << s << '\n';
  } else {
    std::ostringstream s;
    s.imbue(std::locale::classic());
    if constexpr (std::is_floating_point_v<T>) s.precision(std::numeric_limits<T>::max_digits10);
    for (std::size_t i = 0; i < v.size(); ++i) {
      if (i % 12 == 0) s << (i ? "\n" : "") << "          ";
      else s << ' ';
      if constexpr (std::is_same_v<T, std::uint8_t>)
        s << static_cast<int>(v[i]);
      else
        s << v[i];
    }
    out << s.str() << '\n';
  }
  out << "        </DataArray>\n";
}

template <class D>
VtuArray vtu_array_from(std::string name, const Eigen::MatrixBase<D>& m) {
  using T = vtu_storage_t<typename D::Scalar>;
  static_assert(std::is_arithmetic_v<typename D::Scalar>, "vtu: data must be floating-point or integer");
  if (m.cols() < 1 || m.cols() > 9) throw ArgumentError("vtu: array '" + name + "' needs 1 to 9 columns, has " + std::to_string(m.cols()));
  VtuArray a;
  a.name = std::move(name);
  a.components = static_cast<int>(m.cols());
  std::vector<T> v(static_cast<std::size_t>(m.size()));
  for (Index i = 0; i < m.rows(); ++i)
    for (Index j = 0; j < m.cols(); ++j) {
      const auto x = m(i, j);
      if constexpr (std::is_integral_v<typename D::Scalar>)
        if (!std::in_range<T>(x)) throw ArgumentError("vtu: array '" + a.name + "' value out of Int64 range");
      v[static_cast<std::size_t>(i * m.cols() + j)] = static_cast<T>(x);
    }
  a.values = std::move(v);
  return a;
}

}  // namespace detail

/// One unstructured grid: #V points, #T tetrahedra and #F triangles (cells are numbered tets first,
/// then triangles), named point data (#V tuples) and cell data (#T+#F tuples).
class VtuGrid {
 public:
  VtuGrid() = default;
  template <class S>
  explicit VtuGrid(const TetMesh<S>& m) {
    set_points(m.V);
    set_tets(m.T);
  }
  template <class S>
  explicit VtuGrid(const TriMesh<S>& m) {
    set_points(m.V);
    set_triangles(m.F);
  }

  /// #V×3 positions; float stays Float32, other scalars are written as Float64.
  template <class D>
  VtuGrid& set_points(const Eigen::MatrixBase<D>& V) {
    if (V.cols() != 3) throw ShapeError("vtu points", {-1, 3}, {V.rows(), V.cols()});
    using T = std::conditional_t<std::is_same_v<typename D::Scalar, float>, float, double>;
    std::vector<T> p(static_cast<std::size_t>(V.size()));
    for (Index i = 0; i < V.rows(); ++i)
      for (Index c = 0; c < 3; ++c) p[static_cast<std::size_t>(3 * i + c)] = static_cast<T>(V(i, c));
    points_ = std::move(p);
    num_points_ = V.rows();
    return *this;
  }
  /// #T×4 tetrahedra (VTK_TETRA; same vertex order as TetMesh).
  template <class D>
  VtuGrid& set_tets(const Eigen::MatrixBase<D>& T) {
    if (T.cols() != 4) throw ShapeError("vtu tets", {-1, 4}, {T.rows(), T.cols()});
    tets_ = flatten(T);
    return *this;
  }
  /// #F×3 triangles (VTK_TRIANGLE).
  template <class D>
  VtuGrid& set_triangles(const Eigen::MatrixBase<D>& F) {
    if (F.cols() != 3) throw ShapeError("vtu triangles", {-1, 3}, {F.rows(), F.cols()});
    tris_ = flatten(F);
    return *this;
  }
  /// Point data: a vector (#V) or #V×k matrix (k = 3 for vectors); double/float/int32/int64 kept.
  template <class D>
  VtuGrid& add_point_data(std::string name, const Eigen::MatrixBase<D>& values) {
    point_data_.push_back(detail::vtu_array_from(std::move(name), values));
    return *this;
  }
  /// Cell data: one row per cell, tets first then triangles.
  template <class D>
  VtuGrid& add_cell_data(std::string name, const Eigen::MatrixBase<D>& values) {
    cell_data_.push_back(detail::vtu_array_from(std::move(name), values));
    return *this;
  }

  Index num_points() const { return num_points_; }
  Index num_tets() const { return static_cast<Index>(tets_.size() / 4); }
  Index num_triangles() const { return static_cast<Index>(tris_.size() / 3); }
  Index num_cells() const { return num_tets() + num_triangles(); }
  const std::vector<VtuArray>& point_data() const { return point_data_; }
  const std::vector<VtuArray>& cell_data() const { return cell_data_; }

  /// Throws MeshError for vertex indices outside [0, #V), ShapeError for data of the wrong length
  /// and ArgumentError for duplicate names.
  void validate() const {
    auto check_cells = [&](const std::vector<std::int64_t>& c, int k, const char* kind) {
      for (std::size_t i = 0; i < c.size(); ++i)
        if (c[i] < 0 || c[i] >= num_points_)
          throw MeshError(kind, static_cast<std::int64_t>(i / static_cast<std::size_t>(k)),
                          "vertex index " + std::to_string(c[i]) + " outside [0, " + std::to_string(num_points_) + ")");
    };
    check_cells(tets_, 4, "tet");
    check_cells(tris_, 3, "triangle");
    auto check_data = [](const std::vector<VtuArray>& arrays, Index n, const char* where) {
      for (std::size_t i = 0; i < arrays.size(); ++i) {
        if (arrays[i].tuples() != n)
          throw ShapeError(std::string("vtu ") + where + " data '" + arrays[i].name + "'", {n, arrays[i].components},
                           {arrays[i].tuples(), arrays[i].components});
        for (std::size_t j = 0; j < i; ++j)
          if (arrays[j].name == arrays[i].name)
            throw ArgumentError(std::string("vtu: duplicate ") + where + " data name '" + arrays[i].name + "'");
      }
    };
    check_data(point_data_, num_points_, "point");
    check_data(cell_data_, num_cells(), "cell");
  }

  /// The whole .vtu document.
  std::string to_string(VtuFormat fmt = VtuFormat::Binary) const {
    validate();
    std::ostringstream out;
    out << "<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\""
        << (std::endian::native == std::endian::little ? "LittleEndian" : "BigEndian") << "\" header_type=\"UInt64\">\n"
        << "  <UnstructuredGrid>\n    <Piece NumberOfPoints=\"" << num_points_ << "\" NumberOfCells=\"" << num_cells()
        << "\">\n";
    auto data = [&](const std::vector<VtuArray>& arrays, const char* tag) {
      if (arrays.empty()) return;
      out << "      <" << tag << ">\n";
      for (const auto& a : arrays)
        std::visit([&](const auto& v) { detail::vtu_data_array(out, a.name, a.components, v, fmt); }, a.values);
      out << "      </" << tag << ">\n";
    };
    data(point_data_, "PointData");
    data(cell_data_, "CellData");
    out << "      <Points>\n";
    std::visit([&](const auto& p) { detail::vtu_data_array(out, "Points", 3, p, fmt); }, points_);
    out << "      </Points>\n      <Cells>\n";
    std::vector<std::int64_t> conn(tets_);
    conn.insert(conn.end(), tris_.begin(), tris_.end());
    std::vector<std::int64_t> offsets(static_cast<std::size_t>(num_cells()));
    std::vector<std::uint8_t> types(offsets.size());
    std::int64_t o = 0;
    for (std::size_t c = 0; c < offsets.size(); ++c) {
      const bool tet = static_cast<Index>(c) < num_tets();
      o += tet ? 4 : 3;
      offsets[c] = o;
      types[c] = tet ? vtk_tetra : vtk_triangle;
    }
    // Int32 cells where every index and offset fits (half the bytes: connectivity dominates a
    // surface series' files), Int64 otherwise
    if (num_points_ <= std::numeric_limits<std::int32_t>::max() && o <= std::numeric_limits<std::int32_t>::max()) {
      detail::vtu_data_array(out, "connectivity", 1, std::vector<std::int32_t>(conn.begin(), conn.end()), fmt);
      detail::vtu_data_array(out, "offsets", 1, std::vector<std::int32_t>(offsets.begin(), offsets.end()), fmt);
    } else {
      detail::vtu_data_array(out, "connectivity", 1, conn, fmt);
      detail::vtu_data_array(out, "offsets", 1, offsets, fmt);
    }
    detail::vtu_data_array(out, "types", 1, types, fmt);
    out << "      </Cells>\n    </Piece>\n  </UnstructuredGrid>\n</VTKFile>\n";
    return out.str();
  }

 private:
  template <class D>
  static std::vector<std::int64_t> flatten(const Eigen::MatrixBase<D>& c) {
    static_assert(std::is_integral_v<typename D::Scalar>, "vtu: cell indices must be integers");
    std::vector<std::int64_t> v(static_cast<std::size_t>(c.size()));
    for (Index i = 0; i < c.rows(); ++i)
      for (Index j = 0; j < c.cols(); ++j) v[static_cast<std::size_t>(i * c.cols() + j)] = static_cast<std::int64_t>(c(i, j));
    return v;
  }

  std::variant<std::vector<double>, std::vector<float>> points_;
  Index num_points_ = 0;
  std::vector<std::int64_t> tets_, tris_;
  std::vector<VtuArray> point_data_, cell_data_;
};

/// Writes a grid to a .vtu file, atomically (io/atomic_file.hpp): WriteError when it cannot be
/// written, the previous file then unchanged.
inline void write_vtu(const std::filesystem::path& path, const VtuGrid& grid, VtuFormat fmt = VtuFormat::Binary) {
  write_file_atomic(path, grid.to_string(fmt));
}

/// Writes a .pvd collection: one DataSet per (time, file) with `file` relative to the .pvd's folder
/// (atomically, like write_vtu).
inline void write_pvd(const std::filesystem::path& path, const std::vector<std::pair<double, std::string>>& frames) {
  std::ostringstream out;
  out.imbue(std::locale::classic());
  out.precision(17);
  out << "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\""
      << (std::endian::native == std::endian::little ? "LittleEndian" : "BigEndian") << "\">\n  <Collection>\n";
  for (const auto& [t, file] : frames)
    out << "    <DataSet timestep=\"" << t << "\" group=\"\" part=\"0\" file=\"" << detail::vtu_xml_escape(file) << "\"/>\n";
  out << "  </Collection>\n</VTKFile>\n";
  write_file_atomic(path, out.str());
}

/// A time series written frame by frame: add() writes `<stem>/<stem>_<index>.vtu` next to the .pvd
/// and rewrites the .pvd, so the collection on disk is valid after every frame (a run stopped
/// midway still opens in ParaView).
class PvdWriter {
 public:
  explicit PvdWriter(std::filesystem::path pvd, VtuFormat fmt = VtuFormat::Binary) : pvd_(std::move(pvd)), fmt_(fmt) {
    const auto dir = pvd_.parent_path() / pvd_.stem();
    std::error_code ec;
    std::filesystem::create_directories(dir, ec);
    if (ec) throw WriteError(dir.string(), "cannot create the folder of the frames of " + pvd_.string() + ": " + ec.message(), ec.value());
  }

  /// Writes one frame at `time`; returns the path of its .vtu.
  std::filesystem::path add(double time, const VtuGrid& grid) {
    char index[16];
    std::snprintf(index, sizeof index, "%06zu", frames_.size());
    const std::string rel = pvd_.stem().string() + "/" + pvd_.stem().string() + "_" + index + ".vtu";
    const auto file = pvd_.parent_path() / rel;
    write_vtu(file, grid, fmt_);
    frames_.emplace_back(time, rel);
    write_pvd(pvd_, frames_);
    return file;
  }
  std::size_t size() const { return frames_.size(); }
  const std::filesystem::path& path() const { return pvd_; }

 private:
  std::filesystem::path pvd_;
  VtuFormat fmt_;
  std::vector<std::pair<double, std::string>> frames_;
};

}  // namespace simsr::io
