/// \file
/// simsr.io's readers and writers: every mesh format by extension (read_mesh / write_mesh: .obj,
/// .msh 2.2/4.1, .node/.ele/.face, .mesh, and .vtu for writing, with point and cell data through
/// write_vtu), .npy and .npz through the library's own parsers (their checks and typed errors, not
/// NumPy's), and the paired-frame files of the data area. Writes are atomic, as in C++.
#include "common.hpp"

#include <simsr/data/paired_frames.hpp>
#include <simsr/io/io.hpp>

namespace simsr::python {
namespace {

/// An NpyArray as a NumPy array that takes over its bytes (no copy): the capsule owns them.
py::array to_numpy(io::NpyArray&& a) {
  a.validate();
  const py::dtype dtype(a.dtype.descr());
  std::vector<py::ssize_t> shape(a.shape.begin(), a.shape.end()), strides(a.shape.size());
  py::ssize_t step = py::ssize_t(a.dtype.itemsize);
  for (std::size_t i = 0; i < shape.size(); ++i) {  // C order: last axis fastest; Fortran: first
    const std::size_t axis = a.fortran_order ? i : shape.size() - 1 - i;
    strides[axis] = step;
    step *= std::max<py::ssize_t>(shape[axis], 1);
  }
  auto* bytes = new std::vector<std::byte>(std::move(a.bytes));
  py::capsule owner(bytes, [](void* p) { delete static_cast<std::vector<std::byte>*>(p); });
  return py::array(dtype, shape, strides, bytes->data(), owner);
}

/// A NumPy array as an NpyArray (its bytes copied in C order: the writer needs them contiguous).
io::NpyArray from_numpy(const py::handle& h, const std::string& what) {
  py::array a = py::array::ensure(h);
  if (!a) throw ArgumentError(what + ": not convertible to a NumPy array");
  const std::string descr = py::str(a.dtype().attr("str"));
  const auto dtype = io::NpyDType::parse(descr);
  if (!dtype)
    throw ArgumentError(what + ": dtype " + descr + " is not one simsr writes (bool, int8..int64, uint8..uint64, float32/64, unicode)");
  a = py::array::ensure(a, py::array::c_style);
  io::NpyArray out;
  out.dtype = *dtype;
  out.shape.assign(a.shape(), a.shape() + a.ndim());
  out.bytes.resize(std::size_t(a.nbytes()));
  if (a.nbytes()) std::memcpy(out.bytes.data(), a.data(), std::size_t(a.nbytes()));
  out.source = what;
  return out;
}

io::MshVersion msh_version_of(const std::string& v) {
  if (v == "4.1") return io::MshVersion::v41;
  if (v == "2.2") return io::MshVersion::v22;
  throw ArgumentError("msh_version: expected '4.1' or '2.2', got '" + v + "'");
}

io::VtuFormat vtu_format_of(const std::string& f) {
  if (f == "binary") return io::VtuFormat::Binary;
  if (f == "ascii") return io::VtuFormat::Ascii;
  throw ArgumentError("vtu format: expected 'binary' or 'ascii', got '" + f + "'");
}

std::string format_name(io::MeshFormat f) {
  switch (f) {
    case io::MeshFormat::Obj: return "obj";
    case io::MeshFormat::Msh: return "msh";
    case io::MeshFormat::Tetgen: return "tetgen";
    case io::MeshFormat::Medit: return "medit";
    case io::MeshFormat::Vtu: return "vtu";
  }
  return "?";
}

/// A data array for a VTU file: float64/float32/int32/int64 kept, other integers widened to
/// int64, bool to int32; shape (n,) or (n, k).
template <class Add>
void add_vtu_array(const std::string& name, const py::handle& h, Add&& add) {
  py::array a = py::array::ensure(h);
  if (!a || (a.ndim() != 1 && a.ndim() != 2)) throw ArgumentError("vtu data '" + name + "': expected a 1-d or 2-d array");
  const char kind = a.dtype().kind();
  auto as = [&](auto tag) {
    using T = decltype(tag);
    auto v = py::array_t<T, py::array::c_style | py::array::forcecast>::ensure(a);
    const Index rows = a.shape(0), cols = a.ndim() == 2 ? a.shape(1) : 1;
    add(name, Eigen::Map<const Eigen::Matrix<T, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>(v.data(), rows, cols));
  };
  if (kind == 'f' && a.itemsize() == 4)
    as(float{});
  else if (kind == 'f')
    as(double{});
  else if ((kind == 'i' && a.itemsize() <= 4) || kind == 'b')
    as(std::int32_t{});
  else if (kind == 'i' || kind == 'u')
    as(std::int64_t{});
  else
    throw ArgumentError("vtu data '" + name + "': dtype " + std::string(py::str(a.dtype())) + " is not numeric");
}

/// (F, V, 3) frames of a paired-frame set as a NumPy view into it.
py::array frames_view(data::FrameMatrix<Scalar>& m, Index vertices, py::handle owner) {
  return py::array(py::dtype::of<double>(), {py::ssize_t(m.rows()), py::ssize_t(vertices), py::ssize_t(3)},
                   {py::ssize_t(m.cols() * 8), py::ssize_t(24), py::ssize_t(8)}, m.data(), owner);
}

/// (F, V, 3) float64 frames copied into an F×3V frame matrix (ShapeError for another shape).
data::FrameMatrix<Scalar> frame_matrix(const py::handle& h, const std::string& what) {
  auto a = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(h);
  if (!a || a.ndim() != 3 || a.shape(2) != 3)
    throw ShapeError(what + " (frames, vertices, 3)", {-1, -1, 3},
                     a ? std::vector<std::int64_t>(a.shape(), a.shape() + a.ndim()) : std::vector<std::int64_t>{});
  return Eigen::Map<const data::FrameMatrix<Scalar>>(a.data(), a.shape(0), 3 * a.shape(1));
}

}  // namespace

void bind_io(py::module_& m) {
  using MeshData = io::MeshData<Scalar>;
  py::class_<MeshData>(m, "MeshData", "What a mesh file holds: vertices V (n, 3) with tets T (t, 4) and/or triangles F (f, 3).")
      .def_property_readonly("V", [](py::object self) { return view_of(self.cast<MeshData&>().V, self); })
      .def_property_readonly("T", [](py::object self) { return view_of(self.cast<MeshData&>().T, self); })
      .def_property_readonly("F", [](py::object self) { return view_of(self.cast<MeshData&>().F, self); })
      .def_readonly("polygons", &MeshData::polygons, "OBJ: the polygon count before triangulation (0 otherwise)")
      .def_property_readonly("format", [](const MeshData& d) { return format_name(d.format); })
      .def_readonly("format_detail", &MeshData::format_detail)
      .def("__repr__", [](const MeshData& d) {
        return "<simsr.MeshData " + d.format_detail + ": " + std::to_string(d.V.rows()) + " vertices, " + std::to_string(d.T.rows()) +
               " tets, " + std::to_string(d.F.rows()) + " triangles>";
      });

  m.def("read_mesh", [](const std::filesystem::path& path) { return io::read_mesh<Scalar>(path); }, "path"_a,
        "Reads any mesh file by its extension (.obj, .msh, .node/.ele/.face, .mesh). ParseError names the file and line.",
        py::call_guard<py::gil_scoped_release>());
  m.def(
      "write_mesh",
      [](const std::filesystem::path& path, const py::handle& V, const py::handle& T, const py::handle& F, const std::string& msh_version,
         const std::string& vtu_format) {
        MeshData d;
        d.V = points_from(V, "write_mesh: V");
        d.T = T.is_none() ? Tets(0, 4) : index_matrix<4>(T, "write_mesh: T");
        d.F = F.is_none() ? Tris(0, 3) : index_matrix<3>(F, "write_mesh: F");
        io::MeshWriteOptions o{msh_version_of(msh_version), vtu_format_of(vtu_format)};
        py::gil_scoped_release release;
        io::write_mesh(path, d, o);
      },
      "path"_a, "V"_a, "T"_a = py::none(), "F"_a = py::none(), py::kw_only(), "msh_version"_a = "4.1", "vtu_format"_a = "binary",
      "Writes vertices with tets and/or triangles in the format of path's extension (.obj .msh .node/.ele .mesh .vtu), atomically.");
  m.def(
      "write_vtu",
      [](const std::filesystem::path& path, const py::handle& V, const py::handle& T, const py::handle& F, const py::dict& point_data,
         const py::dict& cell_data, const std::string& format) {
        io::VtuGrid g;
        g.set_points(points_from(V, "write_vtu: V"));
        if (!T.is_none()) g.set_tets(index_matrix<4>(T, "write_vtu: T"));
        if (!F.is_none()) g.set_triangles(index_matrix<3>(F, "write_vtu: F"));
        for (const auto& [k, v] : point_data)
          add_vtu_array(py::str(k), v, [&](const std::string& n, const auto& a) { g.add_point_data(n, a); });
        for (const auto& [k, v] : cell_data)
          add_vtu_array(py::str(k), v, [&](const std::string& n, const auto& a) { g.add_cell_data(n, a); });
        const auto fmt = vtu_format_of(format);
        py::gil_scoped_release release;
        io::write_vtu(path, g, fmt);
      },
      "path"_a, "V"_a, "T"_a = py::none(), "F"_a = py::none(), py::kw_only(), "point_data"_a = py::dict(), "cell_data"_a = py::dict(),
      "format"_a = "binary",
      "Writes a VTK unstructured grid for ParaView: tets then triangles as cells, named point data (n or n x k) and cell data.");

  m.def("read_npy", [](const std::filesystem::path& path) { return to_numpy(io::read_npy(path)); }, "path"_a,
        "Reads a .npy file with simsr's parser (typed errors); the array takes over the bytes read.");
  m.def(
      "write_npy", [](const std::filesystem::path& path, const py::handle& a) { io::write_npy(path, from_numpy(a, path.string())); }, "path"_a,
      "array"_a, "Writes a .npy file atomically.");
  m.def(
      "read_npz",
      [](const std::filesystem::path& path) {
        io::NpzArrays z;
        {
          py::gil_scoped_release release;
          z = io::read_npz(path);
        }
        py::dict out;
        for (auto& [name, a] : z) out[py::str(name)] = to_numpy(std::move(a));
        return out;
      },
      "path"_a, "Reads every member of a .npz archive (stored or deflated) into a dict of arrays.");
  m.def(
      "write_npz",
      [](const std::filesystem::path& path, const py::dict& arrays, bool compress) {
        io::NpzArrays z;
        for (const auto& [k, v] : arrays) {
          const std::string name = py::str(k);
          z[name] = from_numpy(v, path.string() + ":" + name);
        }
        py::gil_scoped_release release;
        io::write_npz(path, z, compress ? io::NpzCompression::Deflate : io::NpzCompression::Stored);
      },
      "path"_a, "arrays"_a, py::kw_only(), "compress"_a = false, "Writes a dict of arrays as a .npz archive, atomically.");

  using Paired = data::PairedFrames<Scalar>;
  py::class_<Paired>(m, "PairedFrames",
                     "Paired LR/HR frames (positions or displacements): lowres (F, N, 3), highres (F, M, 3), ids, sequences.")
      .def(py::init([](const py::handle& lowres, const py::handle& highres, std::optional<std::vector<std::int64_t>> ids) {
             Paired p;
             p.lowres = frame_matrix(lowres, "PairedFrames: lowres");
             p.highres = frame_matrix(highres, "PairedFrames: highres");
             if (p.lowres.rows() != p.highres.rows())
               throw ShapeError("PairedFrames: highres frames", {p.lowres.rows(), -1, 3}, {p.highres.rows(), p.num_hr(), 3});
             if (ids) {
               if (Index(ids->size()) != p.lowres.rows()) throw ShapeError("PairedFrames: ids", {p.lowres.rows()}, {Index(ids->size())});
               p.ids = *ids;
             } else {
               for (Index f = 0; f < p.lowres.rows(); ++f) p.ids.push_back(f);
             }
             return p;
           }),
           "lowres"_a, "highres"_a, "ids"_a = py::none(), "Copies (F, N, 3) and (F, M, 3) frames; ids default to 0..F-1.")
      .def_property_readonly("lowres", [](py::object self) { auto& p = self.cast<Paired&>(); return frames_view(p.lowres, p.num_lr(), self); })
      .def_property_readonly("highres", [](py::object self) { auto& p = self.cast<Paired&>(); return frames_view(p.highres, p.num_hr(), self); })
      .def_readonly("ids", &Paired::ids)
      .def_property_readonly("sequence_names", [](const Paired& p) { return p.sequence_names; })
      .def_property_readonly("sequence", [](const Paired& p) { return p.sequence; })
      .def_property_readonly("num_frames", &Paired::num_frames)
      .def_property_readonly("num_lr", &Paired::num_lr)
      .def_property_readonly("num_hr", &Paired::num_hr)
      .def("__len__", &Paired::num_frames)
      .def("__repr__", [](const Paired& p) {
        return "<simsr.PairedFrames " + std::to_string(p.num_frames()) + " frames, N = " + std::to_string(p.num_lr()) +
               ", M = " + std::to_string(p.num_hr()) + ">";
      });
  m.def("read_paired_frames", [](const std::filesystem::path& path) { return data::read_paired_frames(path); }, "path"_a,
        "Reads a paired-frame .npz (the bunny's train_frames.npz, a datagen output).", py::call_guard<py::gil_scoped_release>());
  m.def("write_paired_frames", [](const std::filesystem::path& path, const Paired& p) { data::write_paired_frames(path, p); }, "path"_a,
        "frames"_a, "Writes paired frames as simsr's .npz, atomically.", py::call_guard<py::gil_scoped_release>());
}

}  // namespace simsr::python
