/// \file
/// The library's exception hierarchy as Python classes with the same messages and the same fields:
///
///     simsr.Error (RuntimeError)
///       ParseError          .file .line .message
///         WriteError        .errno
///       MeshError (+ ValueError)   .kind .element
///       ShapeError (+ ValueError)  .expected .got
///       ConvergenceError    .iterations .residual
///       NumericalError      .tensor .step
///       ArgumentError (+ ValueError)
#include "common.hpp"

namespace simsr::python {
namespace {

struct ExceptionTypes {
  PyObject* error = nullptr;
  PyObject* parse = nullptr;
  PyObject* write = nullptr;
  PyObject* mesh = nullptr;
  PyObject* shape = nullptr;
  PyObject* convergence = nullptr;
  PyObject* numerical = nullptr;
  PyObject* argument = nullptr;
};
ExceptionTypes types;  // module-lifetime references (the module keeps them as attributes too)

PyObject* new_type(py::module_& m, const char* name, py::tuple bases, const char* doc) {
  const std::string qualified = std::string("simsr.") + name;
  PyObject* t = PyErr_NewExceptionWithDoc(qualified.c_str(), doc, bases.ptr(), nullptr);
  if (!t) throw py::error_already_set();
  m.add_object(name, py::handle(t));  // steals nothing: add_object increments
  return t;
}

/// Raises `type(what)` with the given attributes set on the instance.
void raise(PyObject* type, const char* what, std::initializer_list<std::pair<const char*, py::object>> fields) {
  py::object e = py::reinterpret_steal<py::object>(PyObject_CallFunction(type, "s", what));
  if (!e) return;  // the call set a Python error already
  for (const auto& [name, value] : fields) e.attr(name) = value;
  PyErr_SetObject(type, e.ptr());
}

py::tuple shape_tuple(const std::vector<std::int64_t>& s) {
  py::tuple t(s.size());
  for (std::size_t i = 0; i < s.size(); ++i) t[i] = s[i] < 0 ? py::object(py::none()) : py::object(py::int_(s[i]));
  return t;
}

}  // namespace

void bind_errors(py::module_& m) {
  py::handle runtime(PyExc_RuntimeError), value(PyExc_ValueError);
  types.error = new_type(m, "Error", py::make_tuple(runtime), "Base of every simsr error.");
  py::handle base(types.error);
  types.parse = new_type(m, "ParseError", py::make_tuple(base),
                         "A file could not be read or written: .file, .line (1-based; 0 for binary formats), .message.");
  types.write = new_type(m, "WriteError", py::make_tuple(py::handle(types.parse)),
                         "An output file could not be written (the previous file is left as it was): .errno.");
  types.mesh = new_type(m, "MeshError", py::make_tuple(base, value), "A mesh is invalid: .kind, .element (-1: the whole mesh).");
  types.shape = new_type(m, "ShapeError", py::make_tuple(base, value),
                         "Array shapes disagree: .expected, .got (tuples; None: any size).");
  types.convergence = new_type(m, "ConvergenceError", py::make_tuple(base),
                               "An iterative solver stopped without meeting its tolerance: .iterations, .residual.");
  types.numerical = new_type(m, "NumericalError", py::make_tuple(base),
                             "A non-finite value where none may appear: .tensor, .step (-1: not in a loop).");
  types.argument = new_type(m, "ArgumentError", py::make_tuple(base, value), "A parameter is outside its valid range.");

  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const WriteError& e) {
      raise(types.write, e.what(), {{"file", py::str(e.file())}, {"line", py::int_(e.line())}, {"message", py::str(e.message())},
                                    {"errno", py::int_(e.error_code())}});
    } catch (const ParseError& e) {
      raise(types.parse, e.what(), {{"file", py::str(e.file())}, {"line", py::int_(e.line())}, {"message", py::str(e.message())}});
    } catch (const MeshError& e) {
      raise(types.mesh, e.what(), {{"kind", py::str(e.kind())}, {"element", py::int_(e.element())}});
    } catch (const ShapeError& e) {
      raise(types.shape, e.what(), {{"expected", shape_tuple(e.expected())}, {"got", shape_tuple(e.got())}});
    } catch (const ConvergenceError& e) {
      raise(types.convergence, e.what(), {{"iterations", py::int_(e.iterations())}, {"residual", py::float_(e.residual())}});
    } catch (const NumericalError& e) {
      raise(types.numerical, e.what(), {{"tensor", py::str(e.tensor())}, {"step", py::int_(e.step())}});
    } catch (const ArgumentError& e) {
      raise(types.argument, e.what(), {});
    } catch (const Error& e) {
      raise(types.error, e.what(), {});
    }
  });
}

}  // namespace simsr::python
