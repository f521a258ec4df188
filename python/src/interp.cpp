/// \file
/// simsr.interp: the upsampling problem and every interpolation baseline of the paper's
/// comparison (Embedded, IDW, RBF, MLS, Ridge, LocalLinear, BetaVae) with one interface:
///
///     problem = simsr.UpsamplingProblem(lr_tets, hr_surface)
///     m = simsr.MLS(k=20)                   # keywords: the C++ options' fields
///     m.fit(problem)                        # neighbourhoods computed on demand (k of the method)
///     m.train(displacements, lambda_=-1)    # methods that learn: keywords of their train options
///     hr = m.apply(lr_displacement)         # (N, 3) -> new (M, 3); out=buf writes in place
///
/// Each Python object guards its method with a mutex: several of them reuse scratch buffers in
/// `apply` (one call at a time per object, as in C++), and the GIL is released while they run.
#include "problem.hpp"

#include <mutex>

#include <simsr/interp/interp.hpp>

namespace simsr::python {
namespace {

using Frames = data::PairedFrames<Scalar>;

/// A method with the mutex that serializes calls on it.
template <class I>
struct Method {
  std::unique_ptr<I> impl;  // some methods are immovable (they own networks that point into themselves)
  std::unique_ptr<std::mutex> mutex = std::make_unique<std::mutex>();
  bool fitted = false;
};

/// Sets the fields named by `kw` on a default `Options` (through its Python binding, so the
/// field's type conversion and the message for an unknown name are pybind11's and ours).
template <class Options>
Options options_from(const py::kwargs& kw, const char* who) {
  py::object o = py::cast(Options{});
  for (const auto& [key, value] : kw) {
    std::string name = py::str(key);
    if (name == "lambda_") name = "lambda";  // `lambda` is a Python keyword
    if (!py::hasattr(o, name.c_str())) {
      std::string known;
      for (const auto& a : py::list(o.attr("__dir__")()))
        if (const std::string s = py::str(a); s.rfind("__", 0) != 0) known += (known.empty() ? "" : ", ") + s;
      throw ArgumentError(std::string(who) + ": unknown option '" + name + "' (known: " + known + ")");
    }
    py::object v = py::reinterpret_borrow<py::object>(value);
    if (py::object current = o.attr(name.c_str()); py::isinstance<py::str>(value) && py::hasattr(current.get_type(), "__members__"))
      v = current.get_type()(value);  // an enum by name: an unknown name is our ArgumentError listing the known ones
    o.attr(name.c_str()) = v;
  }
  return o.cast<Options>();
}

/// Neighbours the method's fit reads (its option k, else the paper's 20).
template <class I>
Index neighborhood_k(const I& method) {
  if constexpr (requires { method.options().k; }) return std::max<Index>(method.options().k, 20);
  return 20;
}

template <class I>
using PyClass = py::class_<Method<I>>;

/// fit / apply / train and the sizes, for any interp::Interpolator; the class is registered under
/// its library name (`library_name`, one of interp::method_names()) in `by_name`.
template <class I, class Options>
PyClass<I> bind_method(py::module_& m, py::dict& by_name, const char* library_name, const char* name, const char* doc) {
  PyClass<I> c(m, name, doc);
  by_name[library_name] = c;  // simsr.make_method's table, keyed by interp::method_names()
  const std::string who = name;
  if constexpr (std::is_same_v<Options, void>)
    c.def(py::init([] { return Method<I>{std::make_unique<I>()}; }));
  else
    c.def(py::init([who](const py::kwargs& kw) { return Method<I>{std::make_unique<I>(options_from<Options>(kw, who.c_str()))}; }),
          (std::string("Keywords: the fields of ") + name + "Options (defaults: the paper's).").c_str());
  c.def(
       "fit",
       [](Method<I>& self, Problem& problem, const std::string& policy) {
         fit_on(problem, *self.impl, *self.mutex, neighborhood_k(*self.impl), policy);
         self.fitted = true;
       },
       "problem"_a, py::kw_only(), policy_arg(), "Fits on the problem's rest shapes (computing its neighbourhoods first when needed and absent).")
      .def(
          "apply",
          [who](Method<I>& self, const ConstPointsRef<Scalar>& lr, std::optional<py::array> out, const std::string& policy) {
            if (!self.fitted) throw ArgumentError(who + ".apply before fit");
            return apply_points(*self.impl, *self.mutex, lr, out, policy, who + ".apply");
          },
          "lr_displacement"_a, "out"_a = py::none(), py::kw_only(), policy_arg(),
          "HR displacements (M, 3) from LR displacements (N, 3), both from the rest shapes; into out (float64, C order) when given.")
      .def_property_readonly("num_lr", [](const Method<I>& self) { return self.impl->num_lr(); })
      .def_property_readonly("num_hr", [](const Method<I>& self) { return self.impl->num_hr(); })
      .def_property_readonly("fitted", [](const Method<I>& self) { return self.fitted; });
  if constexpr (interp::TrainableInterpolator<I>) {
    using TrainOptions = typename I::train_options;
    c.def(
        "train",
        [who](Method<I>& self, const Frames& displacements, const std::string& policy, const py::kwargs& kw) {
          if (!self.fitted) throw ArgumentError(who + ".train before fit");
          TrainOptions o = options_from<TrainOptions>(kw, (who + ".train").c_str());
          py::gil_scoped_release release;
          std::lock_guard lock(*self.mutex);
          with_policy(policy, [&](auto p) { self.impl->train(p, displacements, o); });
        },
        "displacements"_a, py::kw_only(), policy_arg(),
        "Learns from paired frames given as displacements from the fitted rest shapes (simsr.displacements); keywords: the train "
        "options' fields (lambda_ for lambda).");
  }
  return c;
}

/// An enum from its name too: simsr.MLS(basis="linear_3d") as well as basis=simsr.MlsBasis.linear_3d.
template <class E>
py::enum_<E> string_enum(py::module_& m, const char* name, std::initializer_list<std::pair<const char*, E>> values) {
  py::enum_<E> e(m, name);
  for (const auto& [n, v] : values) e.value(n, v);
  std::vector<std::pair<std::string, E>> table;
  for (const auto& [n, v] : values) table.emplace_back(n, v);
  e.def(py::init([table, name = std::string(name)](const std::string& s) {
    std::string known;
    for (const auto& [n, v] : table) {
      if (n == s) return v;
      known += (known.empty() ? "" : ", ") + n;
    }
    throw ArgumentError(name + ": unknown value '" + s + "' (known: " + known + ")");
  }));
  py::implicitly_convertible<py::str, E>();
  return e;
}

}  // namespace

void bind_interp(py::module_& m) {
  py::class_<Problem>(m, "UpsamplingProblem",
                      "The rest shapes of one LR -> HR pair (LR tet mesh, HR surface) and their neighbourhoods, computed once and shared.")
      .def(py::init([](TetMesh<Scalar> lr, TriMesh<Scalar> hr) {
             Problem p;
             p.problem.lr = std::move(lr);
             p.problem.hr = std::move(hr);
             return p;
           }),
           "lr"_a, "hr"_a, "Copies both meshes.")
      .def_property_readonly("lr", [](const Problem& p) { return p.problem.lr; }, "A copy of the LR rest mesh.")
      .def_property_readonly("hr", [](const Problem& p) { return p.problem.hr; }, "A copy of the HR rest surface.")
      .def_property(
          "neighborhoods",
          [](const Problem& p) {
            std::lock_guard lock(*p.mutex);
            return p.problem.neighborhoods;
          },
          [](Problem& p, std::optional<neighbors::UpsamplingNeighborhoods> nb) {
            std::lock_guard lock(*p.mutex);
            std::swap(p.problem.neighborhoods, nb);
            try {
              if (p.problem.neighborhoods) p.problem.checked_neighborhoods(1);
            } catch (...) {
              std::swap(p.problem.neighborhoods, nb);  // refused: the problem keeps what it had
              throw;
            }
          },
          "The §3.2 neighbourhoods, a copy (None until computed or set; set ones are checked against the sizes, and refused ones leave "
          "the problem as it was).")
      .def(
          "ensure_neighborhoods",
          [](Problem& p, Index k, const std::string& policy) {
            py::gil_scoped_release release;
            std::lock_guard lock(*p.mutex);
            with_policy(policy, [&](auto pol) { p.problem.ensure_neighborhoods(pol, k); });
          },
          "k"_a = 20, py::kw_only(), policy_arg())
      .def_property_readonly("num_lr", [](const Problem& p) { return p.problem.num_lr(); })
      .def_property_readonly("num_hr", [](const Problem& p) { return p.problem.num_hr(); });

  m.def(
      "displacements",
      [](const Frames& positions, const Eigen::Ref<const Points<>>& lr_rest, const Eigen::Ref<const Points<>>& hr_rest) {
        return data::displacements(positions, lr_rest, hr_rest);
      },
      "frames"_a, "lr_rest"_a, "hr_rest"_a, "Paired frames of positions as displacements from the rest shapes (a new PairedFrames).",
      py::call_guard<py::gil_scoped_release>());
  m.def("method_names", &interp::method_names, "The baselines' names, cheapest first.");

  string_enum<interp::RbfDistance>(m, "RbfDistance", {{"geodesic", interp::RbfDistance::geodesic},
                                                      {"lr_mesh_geodesic", interp::RbfDistance::lr_mesh_geodesic},
                                                      {"euclidean", interp::RbfDistance::euclidean}});
  string_enum<interp::RbfSolver>(m, "RbfSolver", {{"automatic", interp::RbfSolver::automatic},
                                                  {"dense", interp::RbfSolver::dense},
                                                  {"sparse", interp::RbfSolver::sparse}});
  string_enum<interp::MlsBasis>(m, "MlsBasis", {{"per_coordinate", interp::MlsBasis::per_coordinate}, {"linear_3d", interp::MlsBasis::linear_3d}});

  py::class_<interp::IDWOptions>(m, "IDWOptions")
      .def(py::init<>())
      .def_readwrite("k", &interp::IDWOptions::k)
      .def_readwrite("power", &interp::IDWOptions::power)
      .def_readwrite("hit_distance", &interp::IDWOptions::hit_distance);
  py::class_<interp::RBFOptions>(m, "RBFOptions")
      .def(py::init<>())
      .def_readwrite("distance", &interp::RBFOptions::distance)
      .def_readwrite("sigma", &interp::RBFOptions::sigma)
      .def_readwrite("sigma_scale", &interp::RBFOptions::sigma_scale)
      .def_readwrite("degree", &interp::RBFOptions::degree)
      .def_readwrite("regularization", &interp::RBFOptions::regularization)
      .def_readwrite("solver", &interp::RBFOptions::solver)
      .def_readwrite("dense_max", &interp::RBFOptions::dense_max)
      .def_readwrite("truncation", &interp::RBFOptions::truncation)
      .def_readwrite("max_operator_bytes", &interp::RBFOptions::max_operator_bytes)
      .def_readwrite("min_rcond", &interp::RBFOptions::min_rcond)
      .def_readwrite("k", &interp::RBFOptions::k);
  py::class_<interp::MLSOptions>(m, "MLSOptions")
      .def(py::init<>())
      .def_readwrite("basis", &interp::MLSOptions::basis)
      .def_readwrite("degree", &interp::MLSOptions::degree)
      .def_readwrite("k", &interp::MLSOptions::k)
      .def_readwrite("sigma", &interp::MLSOptions::sigma)
      .def_readwrite("sigma_scale", &interp::MLSOptions::sigma_scale)
      .def_readwrite("min_rcond", &interp::MLSOptions::min_rcond);
  py::class_<interp::RidgeOptions>(m, "RidgeOptions").def(py::init<>()).def_readwrite("residual", &interp::RidgeOptions::residual);
  py::class_<interp::RidgeTrainOptions>(m, "RidgeTrainOptions")
      .def(py::init<>())
      .def_readwrite("lambda", &interp::RidgeTrainOptions::lambda)
      .def_readwrite("gcv_log10_lo", &interp::RidgeTrainOptions::gcv_log10_lo)
      .def_readwrite("gcv_log10_hi", &interp::RidgeTrainOptions::gcv_log10_hi)
      .def_readwrite("gcv_steps", &interp::RidgeTrainOptions::gcv_steps)
      .def_readwrite("rank_tolerance", &interp::RidgeTrainOptions::rank_tolerance);
  py::class_<interp::LocalLinearOptions>(m, "LocalLinearOptions").def(py::init<>()).def_readwrite("k", &interp::LocalLinearOptions::k);
  py::class_<interp::LocalLinearTrainOptions>(m, "LocalLinearTrainOptions")
      .def(py::init<>())
      .def_readwrite("lambda", &interp::LocalLinearTrainOptions::lambda)
      .def_readwrite("log10_lo", &interp::LocalLinearTrainOptions::log10_lo)
      .def_readwrite("log10_hi", &interp::LocalLinearTrainOptions::log10_hi)
      .def_readwrite("steps", &interp::LocalLinearTrainOptions::steps)
      .def_readwrite("folds", &interp::LocalLinearTrainOptions::folds);
  py::class_<interp::BetaVaeTrainOptions>(m, "BetaVaeTrainOptions")
      .def(py::init<>())
      .def_readwrite("epochs", &interp::BetaVaeTrainOptions::epochs)
      .def_readwrite("batch_size", &interp::BetaVaeTrainOptions::batch_size)
      .def_readwrite("lr", &interp::BetaVaeTrainOptions::lr)
      .def_readwrite("seed", &interp::BetaVaeTrainOptions::seed)
      .def_readwrite("progress", &interp::BetaVaeTrainOptions::progress);

  py::dict by_name;
  bind_method<interp::Embedded<Scalar>, void>(m, by_name, "embedded", "Embedded", "Barycentric interpolation in the LR tet containing (or nearest to) each HR vertex.");
  bind_method<interp::IDW<Scalar>, interp::IDWOptions>(m, by_name, "idw", "IDW", "Inverse-distance weighting over the §3.2 neighbourhoods (A.1).");
  bind_method<interp::RBF<Scalar>, interp::RBFOptions>(m, by_name, "rbf", "RBF", "Gaussian radial basis functions (A.2, Eq. 9-11).")
      .def_property_readonly("sigma", [](const Method<interp::RBF<Scalar>>& s) { return s.impl->info().sigma; });
  bind_method<interp::MLS<Scalar>, interp::MLSOptions>(m, by_name, "mls", "MLS", "Moving least squares over the §3.2 neighbourhoods (A.3, Eq. 12-16).")
      .def_property_readonly("sigma", [](const Method<interp::MLS<Scalar>>& s) { return s.impl->info().sigma; });
  bind_method<interp::Ridge<Scalar>, interp::RidgeOptions>(m, by_name, "ridge", "Ridge", "Kernel ridge regression over the frames, on Embedded's residual by default.")
      .def_property_readonly("lambda_relative", [](const Method<interp::Ridge<Scalar>>& s) { return s.impl->info().lambda_relative; });
  bind_method<interp::LocalLinear<Scalar>, interp::LocalLinearOptions>(
      m, by_name, "local_linear", "LocalLinear", "Per HR vertex a 3 x 3k linear map of its §3.2 neighbours' displacements, ridge-regularized by cross-validation.")
      .def_property_readonly("lambda_relative", [](const Method<interp::LocalLinear<Scalar>>& s) { return s.impl->info().lambda_relative; });
  bind_method<interp::BetaVaeBaseline<Scalar>, void>(m, by_name, "beta_vae", "BetaVae", "The A.4 beta-VAE from LR to HR displacements (float32 network).");
  for (const auto& name : interp::method_names())  // a baseline added in C++ and not here fails at import, not at make_method
    if (!by_name.contains(name)) throw std::logic_error("simsr module: interp method '" + name + "' has no Python class");
  m.attr("_method_classes") = by_name;
}

}  // namespace simsr::python
