/// \file
/// The scenario datagen from Python: the library's three dataset generators, each one call with
/// the command-line tool's options as keywords (`simsr datagen --scenario face|softdeca|sheet|disk`
/// runs the same functions), resumable (a rerun into the same folder continues a killed run and
/// reuses finished parts; another run's checkpoint is refused), with progress through a Python
/// callback. The GIL is released while they simulate; each callback takes it back for its call,
/// and Ctrl-C is honoured there (PyErr_CheckSignals: the run stops with KeyboardInterrupt, its
/// checkpoints kept).
///
/// The callbacks are captured by pointer to the caller's Python object, never by value: the
/// library copies its std::function options without the GIL, and copying a py::object would
/// touch its reference count without it.
#include "common.hpp"

#include <filesystem>
#include <fstream>
#include <functional>

#include <nlohmann/json.hpp>

#include <simsr/scenario/face/face_dataset.hpp>
#include <simsr/scenario/softdeca/ict_template.hpp>
#include <simsr/scenario/softdeca/softdeca_datagen.hpp>
#include <simsr/scenario/softdeca/sphere_template.hpp>
#include <simsr/shell/cloth_datagen.hpp>

namespace simsr::python {
namespace {

namespace fs = std::filesystem;

/// A line-progress callback for the library: `callback(line)` under the GIL (nothing when None),
/// after a check for Ctrl-C.
std::function<void(const std::string&)> line_progress(const py::object* callback) {
  return [callback](const std::string& line) {
    py::gil_scoped_acquire gil;
    if (PyErr_CheckSignals() != 0) throw py::error_already_set();
    if (!callback->is_none()) (*callback)(line);
  };
}

py::dict cloth_frame_dict(const std::string& sequence, Index frame, Index frames, const shell::ClothFrameReport& coarse,
                          const shell::ClothFrameReport& fine, double coarse_seconds, double fine_seconds) {
  py::dict d;
  d["sequence"] = sequence;
  d["frame"] = frame;
  d["frames"] = frames;
  d["coarse_seconds"] = coarse_seconds;
  d["fine_seconds"] = fine_seconds;
  d["coarse_newton_iterations"] = coarse.newton_iterations;
  d["fine_newton_iterations"] = fine.newton_iterations;
  d["deepest"] = std::min(coarse.deepest, fine.deepest);
  return d;
}

nlohmann::ordered_json read_json(const fs::path& file) {
  std::ifstream in(file);
  if (!in) throw ParseError(file.string(), 0, "cannot open the run's summary");
  return nlohmann::ordered_json::parse(in);
}

}  // namespace

void bind_scenario(py::module_& m) {
  m.def(
      "generate_face_data",
      [](const fs::path& out, const fs::path& kit, const std::string& preset, double lr_cell, double skull_lattice, double hr_max_volume,
         const std::vector<std::string>& performances, const std::vector<fs::path>& controls, Index frames, std::uint64_t seed, Index checkpoint_every,
         Index chunks, Index chunk_overlap, Index vtk_every, bool unseen_forces, Index unseen_frames, const py::object& on_progress,
         const std::string& policy) {
        scenario::FaceDatasetOptions o;
        o.kit = kit;
        o.model = scenario::face_model_preset(preset, lr_cell, skull_lattice, hr_max_volume);
        o.performances = performances;
        o.controls = controls;
        o.frames = frames;
        o.seed = seed;
        o.checkpoint_every = checkpoint_every;
        o.chunks = chunks;
        o.chunk_overlap = chunk_overlap;
        o.vtk_every = vtk_every;
        o.unseen_forces = unseen_forces;
        o.unseen_frames = unseen_frames;
        const auto say = line_progress(&on_progress);
        nlohmann::ordered_json report;
        {
          py::gil_scoped_release release;
          report = with_policy(policy, [&](auto p) { return scenario::generate_face_dataset(p, o, out, say); });
        }
        return python_of(report);
      },
      "out"_a, py::kw_only(), "kit"_a, "preset"_a = "default", "lr_cell"_a = 0.0, "skull_lattice"_a = 0.0, "hr_max_volume"_a = 0.0,
      "performances"_a = std::vector<std::string>{"amazement", "anger", "fear", "pain"}, "controls"_a = std::vector<fs::path>{}, "frames"_a = 120,
      "seed"_a = 1, "checkpoint_every"_a = 10, "chunks"_a = 0, "chunk_overlap"_a = 2, "vtk_every"_a = 10, "unseen_forces"_a = true, "unseen_frames"_a = 40, "on_progress"_a = py::none(),
      policy_arg(),
      "The core paper's face data (`simsr datagen --scenario face`): the anatomical model built from the ICT kit (preset 'default', "
      "'paper-ratio' or 'paper-lr'; lr_cell / skull_lattice in cm and hr_max_volume in cm^3 override it when > 0), each built-in "
      "performance (frames each, seed) and each controls file (.npz: names, weights F x C) simulated at both resolutions into out/"
      "<name>.npz (each performance's frames in `chunks` contiguous chunks after `chunk_overlap` lead-in frames; 0: one), VTU series every "
      "vtk_every frames (0: none), the LR-only unseen-force frames. on_progress(line) receives the "
      "progress lines. Resumable: a rerun continues a killed run and reuses finished performances. Returns the summary "
      "(out/face_data.json) as a dict.");

  m.def(
      "generate_softdeca_data",
      [](const fs::path& out, Index samples, const std::string& template_name, const fs::path& kit, Index layers, Index sphere_level,
         std::uint64_t seed, Index steps, const std::string& solver, std::optional<Index> active_expressions, Index max_iterations,
         Index newton_iterations, bool skip_unconverged, const py::object& on_progress, const std::string& policy) {
        scenario::SoftDecaDatagenOptions o;
        o.samples = samples;
        o.seed = seed;
        o.active_expressions = active_expressions;
        o.simulation.steps = steps;
        o.simulation.max_iterations = max_iterations;
        o.simulation.newton_iterations = newton_iterations;
        o.simulation.solver = scenario::parse_softdeca_solver(solver);
        o.skip_unconverged = skip_unconverged;
        if (template_name != "ict" && template_name != "sphere")
          throw ArgumentError("generate_softdeca_data: template is 'ict' or 'sphere' (got '" + template_name + "')");
        const auto say = line_progress(&on_progress);
        nlohmann::ordered_json report;
        {
          py::gil_scoped_release release;
          report = with_policy(policy, [&](auto p) {
            if (template_name == "sphere") {
              const auto tpl = scenario::sphere_softdeca_template(p, sphere_level, layers);
              return scenario::generate_softdeca_dataset(p, tpl, "sphere level " + std::to_string(sphere_level), o, out, say);
            }
            scenario::SoftDecaTemplateOptions t;
            t.head.layers = layers;
            say("building the layered template from " + kit.string() + " (" + std::to_string(layers) + " layer(s) per shell)");
            const auto tpl = scenario::softdeca_template(p, scenario::read_ict_kit(kit), t);
            return scenario::generate_softdeca_dataset(p, tpl, "ict", o, out, say);
          });
        }
        return python_of(report);
      },
      "out"_a, py::kw_only(), "samples"_a = 100, "template"_a = "ict", "kit"_a = fs::path(), "layers"_a = 1, "sphere_level"_a = 3, "seed"_a = 1,
      "steps"_a = 6, "solver"_a = "local_global", "active_expressions"_a = py::none(), "max_iterations"_a = 5000, "newton_iterations"_a = 100,
      "skip_unconverged"_a = true, "on_progress"_a = py::none(), policy_arg(),
      "SoftDECA's sampled data (`simsr datagen --scenario softdeca`): the layered head template (template 'ict' from the kit folder, or "
      "'sphere', the stand-in ball of icosphere sphere_level), samples parameter sets and expressions simulated on it (solver "
      "'local_global' or 'newton', steps implicit steps each) into out/. A sample no solver settles is left out and listed "
      "(skip_unconverged=False: it stops the run). on_progress(line) receives a line per sample. Resumable. Returns the summary as a dict.");

  m.def(
      "generate_cloth_data",
      [](const std::string& scene, const fs::path& out, Index sequences, Index cells, Index levels, Index fine_cells,
         const std::optional<fs::path>& fine_frames_from, std::optional<std::uint64_t> seed, Index settle_frames, Index checkpoint_every,
         Index sequence_workers, const std::string& stepping, Index step_iterations, std::optional<Index> substeps, const py::object& on_frame,
         const std::string& policy) {
        const shell::ClothDataset d = shell::cloth_dataset(scene);
        shell::ClothDatagenOptions o;
        o.size = shell::scene_size(d, cells, levels, fine_cells);
        if (fine_frames_from) o.fine_frames_from = *fine_frames_from;
        o.sequences = sequences;
        if (seed) o.seed = *seed;
        o.settle_frames = settle_frames;
        o.checkpoint_every = checkpoint_every;
        o.sequence_workers = sequence_workers;
        if (substeps) o.simulation.substeps = *substeps;
        o.simulation.newton = shell::cloth_newton_options(shell::parse_cloth_stepping(stepping), step_iterations);
        const py::object* callback = &on_frame;
        // several workers call it, one at a time (the library's lock); each takes the GIL for it
        o.on_frame = [callback](const std::string& seq, Index f, Index frames, const shell::ClothFrameReport& rc, const shell::ClothFrameReport& rf,
                                double sc, double sf) {
          py::gil_scoped_acquire gil;
          if (PyErr_CheckSignals() != 0) throw py::error_already_set();
          if (!callback->is_none()) (*callback)(cloth_frame_dict(seq, f, frames, rc, rf, sc, sf));
        };
        o.on_settle_frame = o.on_frame;  // the shared start, settled first: sequence "settle"
        {
          py::gil_scoped_release release;
          with_policy(policy, [&](auto p) { shell::generate_cloth_data(p, d, out, o); });
        }
        return python_of(read_json(out / "cloth_data.json"));
      },
      "scene"_a, "out"_a, py::kw_only(), "sequences"_a = 0, "cells"_a = 0, "levels"_a = -1, "fine_cells"_a = 0, "fine_frames_from"_a = py::none(),
      "seed"_a = py::none(), "settle_frames"_a = shell::ClothDatagenOptions{}.settle_frames, "checkpoint_every"_a = shell::ClothDatagenOptions{}.checkpoint_every,
      "sequence_workers"_a = 0, "stepping"_a = "inexact", "step_iterations"_a = 0, "substeps"_a = py::none(), "on_frame"_a = py::none(), policy_arg(),
      "The thin-shell paper's cloth data (`simsr datagen --scenario sheet|disk`): scene 'sheet' or 'disk' simulated at two "
      "resolutions (coarse cells / rings, Loop levels to the fine cloth; 0 / -1: the scene's default), sequences (0: 32 / 16, "
      "every 5th held out) into out/, each sequence_workers at once (0: the policy's threads; the same data for any count); "
      "fine_frames_from takes another dataset's fine frames (the scale study). stepping 'inexact' or 'converged', step_iterations "
      "(0: 3 / 30) and substeps as the tool's. on_frame(dict) is called after every frame (sequence, frame, frames, seconds, Newton "
      "iterations, deepest), the shared start's settling as sequence 'settle'. Resumable. Returns the summary "
      "(out/cloth_data.json) as a dict.");
}

}  // namespace simsr::python
