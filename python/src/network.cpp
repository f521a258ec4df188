/// \file
/// simsr.Network: the paper's super-resolution network (interp::Learned over nn's native layers)
/// as a Python object: a config by preset name and/or a dict of NetworkConfig's JSON fields, fit on
/// an UpsamplingProblem, train with progress (a per-epoch callback, Ctrl-C honoured between
/// epochs), resumable checkpoints, apply (inference), save and load of one model file.
#include "problem.hpp"

#include <mutex>
#include <nlohmann/json.hpp>

#include <simsr/interp/learned.hpp>

namespace simsr::python {
namespace {

using Learned = interp::Learned<>;
using Frames = data::PairedFrames<Scalar>;

struct Network {
  std::unique_ptr<Learned> impl;
  std::unique_ptr<std::mutex> mutex = std::make_unique<std::mutex>();
  bool fitted = false;
};

nlohmann::json json_of(const py::handle& o) {
  return nlohmann::json::parse(std::string(py::str(py::module_::import("json").attr("dumps")(o))));
}

/// A preset ("official", "paper") with NetworkConfig fields given as keywords (strict: an unknown
/// field, or one that would not hold, is an ArgumentError naming it).
nn::NetworkConfig config_of(const std::string& preset, const py::dict& fields) { return nn::NetworkConfig::with_fields(preset, json_of(fields)); }

py::dict epoch_dict(const nn::EpochReport& r) {
  py::dict d;
  d["epoch"] = r.epoch;
  d["steps"] = r.steps;
  d["loss"] = r.loss;
  d["recon"] = r.recon;
  d["z_reg"] = r.z_reg;
  d["face_normals"] = r.face_normals;
  d["contact"] = r.contact;
  d["seconds"] = r.seconds;
  d["lr"] = r.lr;
  d["holdout_mean_error"] = r.holdout_mean_error >= 0 ? py::object(py::float_(r.holdout_mean_error)) : py::object(py::none());
  return d;
}

}  // namespace

void bind_network(py::module_& m) {
  py::class_<Network>(m, "Network",
                      "The paper's super-resolution network (§3): LR displacements (N, 3) -> HR displacements (M, 3), float32 inside.")
      .def(py::init([](const std::string& preset, std::uint64_t seed, const py::kwargs& fields) {
             return Network{std::make_unique<Learned>(config_of(preset, fields), seed)};
           }),
           py::kw_only(), "preset"_a = "official", "seed"_a = 0,
           "An untrained network: the preset 'official' (the public PyTorch code's, 706,871 parameters) or 'paper' (§3 and Table 3 "
           "read literally), with any NetworkConfig field given as a keyword (epochs=14, residual=True, ...); seed draws the "
           "initial weights at fit.")
      .def_static(
          "load",
          [](const std::filesystem::path& path) {
            Network n{std::make_unique<Learned>(Learned::from_model_file(path))};
            n.fitted = true;
            return n;
          },
          "path"_a, "A trained network from a model file (Network.save, simsr train): apply works at once.")
      .def_property_readonly("config", [](const Network& n) { return python_of(n.impl->config().to_json()); }, "The config as a dict (JSON).")
      .def(
          "fit",
          [](Network& n, Problem& problem, const std::string& policy) {
            fit_on(problem, *n.impl, *n.mutex, Learned::neighborhoods_needed(n.impl->config()), policy);
            n.fitted = true;
          },
          "problem"_a, py::kw_only(), policy_arg(),
          "Builds the network's geometry from the problem (neighbourhoods, LR graph, residual base) and draws the weights; for a loaded "
          "model, checks that the problem's rest shapes are its own.")
      .def(
          "train",
          [](Network& n, const Frames& displacements, Index epochs, Index batch_size, double lr, std::uint64_t seed, bool progress,
             Index lr_decay_epochs, double lr_decay_gamma, std::optional<Frames> holdout, const std::optional<std::filesystem::path>& checkpoint,
             const std::optional<std::filesystem::path>& resume, py::object on_epoch, const std::string& policy) {
            if (!n.fitted) throw ArgumentError("Network.train before fit");
            interp::NetworkTrainOptions o;
            o.trainer.epochs = epochs;
            o.trainer.batch_size = batch_size;
            o.trainer.lr = lr;
            o.trainer.seed = seed;
            o.trainer.progress = progress;
            o.trainer.lr_decay_epochs = lr_decay_epochs;
            o.trainer.lr_decay_gamma = lr_decay_gamma;
            o.holdout = holdout ? &*holdout : nullptr;
            if (checkpoint) o.checkpoint = *checkpoint;
            if (resume) o.resume = *resume;
            // by pointer: the trainer may copy its options without the GIL (a py::object's copy
            // would change its reference count unlocked)
            const py::object* callback = &on_epoch;
            o.trainer.on_epoch = [callback](const nn::EpochReport& r) {
              py::gil_scoped_acquire gil;
              if (PyErr_CheckSignals() != 0) throw py::error_already_set();  // Ctrl-C between epochs
              if (!callback->is_none()) (*callback)(epoch_dict(r));
            };
            py::gil_scoped_release release;
            std::lock_guard lock(*n.mutex);
            with_policy(policy, [&](auto p) { n.impl->train(p, displacements, o); });
          },
          "displacements"_a, py::kw_only(), "epochs"_a = -1, "batch_size"_a = -1, "lr"_a = -1.0, "seed"_a = 0, "progress"_a = false,
          "lr_decay_epochs"_a = 0, "lr_decay_gamma"_a = 0.5, "holdout"_a = py::none(), "checkpoint"_a = py::none(),
          "resume"_a = py::none(), "on_epoch"_a = py::none(), policy_arg(),
          "Trains on paired frames of displacements from the rest shapes (-1: the config's epochs, batch size, lr). on_epoch(dict) is "
          "called after every epoch (loss terms, seconds, held-out mean error when holdout is given); checkpoint is written after "
          "every epoch and resume continues one (the same config, options and data, or an error naming what differs).")
      .def(
          "apply",
          [](Network& n, const ConstPointsRef<Scalar>& lr, std::optional<py::array> out, const std::string& policy) {
            if (!n.fitted) throw ArgumentError("Network.apply before fit");
            return apply_points(*n.impl, *n.mutex, lr, out, policy, "Network.apply");
          },
          "lr_displacement"_a, "out"_a = py::none(), py::kw_only(), policy_arg(),
          "Inference: HR displacements (M, 3) from LR displacements (N, 3); into out (float64, C order) when given.")
      .def(
          "save",
          [](const Network& n, const std::filesystem::path& path) {
            if (!n.fitted) throw ArgumentError("Network.save before fit");
            py::gil_scoped_release release;
            std::lock_guard lock(*n.mutex);
            n.impl->save(path);
          },
          "path"_a, "Writes the self-contained model file (weights, config, rest shapes), atomically.")
      .def_property_readonly("num_parameters", [](const Network& n) { return n.fitted ? n.impl->network().store().num_parameters() : Index(0); })
      .def_property_readonly("num_lr", [](const Network& n) { return n.impl->num_lr(); })
      .def_property_readonly("num_hr", [](const Network& n) { return n.impl->num_hr(); })
      .def_property_readonly("epoch", [](const Network& n) { return n.impl->epoch(); })
      .def_property_readonly("steps", [](const Network& n) { return n.impl->steps(); })
      .def_property_readonly("history", [](const Network& n) {
        py::list l;
        for (const auto& r : n.impl->history()) l.append(epoch_dict(r));
        return l;
      });
}

}  // namespace simsr::python
