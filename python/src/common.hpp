#pragma once
/// \file
/// What every translation unit of the Python module shares: pybind11 with its Eigen, NumPy, STL
/// and filesystem casters, the `policy=` keyword, and the one declaration per area that
/// module.cpp calls.
///
/// Copies, and why (the module's docstring repeats this for Python users):
/// - N×3 positions and displacements passed to per-frame calls (`apply`) are read in place when
///   they are C-contiguous float64 (simsr::ConstPointsRef); another dtype or layout is converted
///   once by pybind11. `apply(..., out=a)` writes into `a` in place (float64, C order, writable).
/// - Arrays a function returns are moved out of the library's Eigen matrix into the NumPy array
///   (pybind11 hands the matrix's buffer over): no element is copied.
/// - Array properties of objects (`TetMesh.V`, `KnnResult.indices`, ...) are views into the C++
///   object, kept alive by the view: writing them writes the object.
/// - Meshes, frames and anything a call keeps (`TetMesh(V, T)`, `train(...)`) are copied into
///   library-owned storage: the library's types own their memory, and a kept view of a NumPy
///   array would dangle when Python frees it.

#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <limits>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include <simsr/core/error.hpp>
#include <simsr/core/parallel.hpp>
#include <simsr/core/types.hpp>

namespace simsr::python {

namespace py = pybind11;
using namespace pybind11::literals;

/// Calls f(exec::omp) or f(exec::seq) as Python's `policy=` keyword names it ("omp", the default
/// everywhere, or "seq"); ArgumentError (Python: simsr.ArgumentError) for anything else.
template <class F>
decltype(auto) with_policy(const std::string& policy, F&& f) {
  if (policy == "omp") return f(exec::omp);
  if (policy == "seq") return f(exec::seq);
  throw ArgumentError("policy: expected 'omp' or 'seq', got '" + policy + "'");
}

/// A JSON value of the library's (a config, a run's summary) as the Python object json.loads makes
/// of it (dict, list, str, int, float, bool, None).
template <class Json>
py::object python_of(const Json& j) {
  return py::module_::import("json").attr("loads")(j.dump());
}

/// The `policy` keyword argument, keyword-only, default "omp".
inline py::arg_v policy_arg() { return py::arg("policy") = std::string("omp"); }

/// A C++ array as a NumPy view of it, `owner` (a Python object holding it) kept alive by the view:
/// writable for a non-const array, read-only for a const one.
template <class Matrix>
py::array view_of(Matrix& m, py::handle owner) {
  using Plain = std::remove_const_t<Matrix>;
  if constexpr (std::is_const_v<Matrix>)
    return py::cast(Eigen::Ref<const Plain>(m), py::return_value_policy::reference_internal, owner);
  else
    return py::cast(Eigen::Ref<Plain>(m), py::return_value_policy::reference_internal, owner);
}

/// `out`, an (rows, 3) float64 C-ordered writable array, as the PointsRef a call writes into.
/// TypeError for another dtype, order or a read-only array (a converted copy would be written and
/// lost), ShapeError for another shape.
inline PointsRef<Scalar> out_points(const py::array& out, Index rows, const std::string& what) {
  if (!out.dtype().is(py::dtype::of<double>()))
    throw py::type_error(what + ": out must be a float64 array, got " + std::string(py::str(out.dtype())));
  if (out.ndim() != 2 || out.shape(0) != rows || out.shape(1) != 3)
    throw ShapeError(what + ": out", {rows, 3}, std::vector<std::int64_t>(out.shape(), out.shape() + out.ndim()));
  if (!(out.flags() & py::array::c_style)) throw py::type_error(what + ": out must be C-contiguous (row-major)");
  if (!out.writeable()) throw py::type_error(what + ": out is read-only");
  return Eigen::Map<Points<Scalar>>(static_cast<double*>(const_cast<void*>(out.data())), rows, 3);
}

/// An integer NumPy array (any integer dtype) as an #rows×Cols int32 index matrix (Tets, Tris,
/// Edges; Cols = 1: an IndexVector), checked: ShapeError for another shape, ArgumentError naming the first entry outside
/// int32's range or a non-integer dtype (pybind11's own cast would wrap int64 silently).
template <int Cols>
using IndexMatrix = Eigen::Matrix<VIndex, Eigen::Dynamic, Cols, Cols == 1 ? Eigen::ColMajor : Eigen::RowMajor>;

template <int Cols>
IndexMatrix<Cols> index_matrix(const py::handle& h, const std::string& what) {
  py::array a = py::array::ensure(h);
  if (!a) throw ArgumentError(what + ": expected an integer array");
  if (a.size() == 0 && a.ndim() <= 2)  // an empty list or array: no elements, any dtype
    return IndexMatrix<Cols>(0, Cols);
  const char kind = a.dtype().kind();
  if (kind != 'i' && kind != 'u') throw ArgumentError(what + ": expected an integer array, got dtype " + std::string(py::str(a.dtype())));
  if (a.ndim() != 2 || a.shape(1) != Cols)
    throw ShapeError(what, {-1, Cols}, std::vector<std::int64_t>(a.shape(), a.shape() + a.ndim()));
  auto v = py::array_t<std::int64_t, py::array::c_style | py::array::forcecast>::ensure(a);
  const std::int64_t* d = v.data();
  IndexMatrix<Cols> out(a.shape(0), Cols);
  for (Index i = 0; i < out.size(); ++i) {
    if (d[i] < std::numeric_limits<VIndex>::min() || d[i] > std::numeric_limits<VIndex>::max())
      throw ArgumentError(what + ": entry (" + std::to_string(i / Cols) + ", " + std::to_string(i % Cols) + ") = " + std::to_string(d[i]) +
                          " is outside the 32-bit index range");
    out.data()[i] = VIndex(d[i]);
  }
  return out;
}

/// #rows×3 float64 positions copied from any real array (ShapeError for another shape).
inline Points<> points_from(const py::handle& h, const std::string& what) {
  auto a = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(h);
  if (!a) throw ArgumentError(what + ": expected a real (N, 3) array");
  if (a.size() == 0 && a.ndim() <= 2) return Points<>(0, 3);
  if (a.ndim() != 2 || a.shape(1) != 3) throw ShapeError(what, {-1, 3}, std::vector<std::int64_t>(a.shape(), a.shape() + a.ndim()));
  return Eigen::Map<const Points<>>(a.data(), a.shape(0), 3);
}

/// `method.apply(policy, lr, hr)` with the GIL released and `mutex` held (methods reuse scratch
/// buffers: one call at a time per object): into `out` when given (returned), else a new (rows, 3)
/// array that takes over the result's buffer.
template <class Method>
py::object apply_points(Method& method, std::mutex& mutex, const ConstPointsRef<Scalar>& lr, const std::optional<py::array>& out,
                        const std::string& policy, const std::string& who) {
  const Index rows = method.num_hr();
  auto run = [&](PointsRef<Scalar> hr) {
    py::gil_scoped_release release;
    std::lock_guard lock(mutex);
    with_policy(policy, [&](auto p) { method.apply(p, lr, hr); });
  };
  if (out) {
    run(out_points(*out, rows, who));
    return *out;
  }
  Points<Scalar> hr(rows, 3);
  run(hr);
  return py::cast(std::move(hr));
}

void bind_errors(py::module_& m);
void bind_io(py::module_& m);
void bind_mesh(py::module_& m);
void bind_neighbors(py::module_& m);
void bind_interp(py::module_& m);
void bind_network(py::module_& m);
void bind_physics(py::module_& m);
void bind_scenario(py::module_& m);

}  // namespace simsr::python
