/// \file
/// `import simsr`: the module's entry point. Each library area is bound in its own file.
#include "common.hpp"

PYBIND11_MODULE(_simsr, m) {
  using namespace simsr::python;
  m.doc() =
      "simsr: physics-based simulation super-resolution (the C++ library, bound with pybind11).\n\n"
      "Every call that runs parallel code takes the execution policy as the keyword policy='omp'\n"
      "(default) or 'seq'; long calls release the GIL. Errors are simsr.Error subclasses with the\n"
      "library's messages (simsr.ParseError, simsr.ShapeError, ...).\n\n"
      "Copies: N x 3 frames passed to apply() are read in place when C-contiguous float64 (other\n"
      "dtypes and layouts are converted once); apply(..., out=a) writes into a; returned arrays take\n"
      "over the library's buffer; array attributes of objects are views into them; meshes and\n"
      "training frames are copied into the objects that keep them.";
  m.attr("__version__") = SIMSR_PYTHON_VERSION;
  bind_errors(m);
  bind_io(m);
  bind_mesh(m);
  bind_neighbors(m);
  bind_interp(m);
  bind_network(m);
  bind_physics(m);
  bind_scenario(m);
}
