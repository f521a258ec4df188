#pragma once
// `simsr train --lr-rest L --hr-rest H --frames TRAIN.npz [--neighbors N.npz | --official-neighbors DIR]
//   [--profile official|paper] [--epochs E] [--seed S] [--holdout-every 4] --out MODEL.npz`
// Trains the super-resolution network (SPEC §7) on paired frames (`lowres` F×N×3, `highres`
// F×M×3 absolute positions, optional `frame` ids). Frames f with f % holdout == 0 are held out
// (never trained on) and evaluated after every epoch against the Embedded baseline on the same
// frames. Writes MODEL.npz (one self-contained file: weights, config, geometry), a checkpoint
// every epoch when --checkpoint is given (resumable with --resume), and with --out-dir the
// per-epoch history as CSV and SVG. stdout: one JSON object with the run's figures.
// Under `mpirun -np R` (a build with SIMSR_WITH_MPI): data-parallel, each rank its block of every
// global batch (mpi::MpiBatchGroup); the files are the single process's, bit for bit, and rank 0
// alone writes them and prints.
#include <simsr/data/data.hpp>
#include <simsr/eval/evaluate.hpp>
#include <simsr/eval/training_history.hpp>
#include <simsr/interp/interp.hpp>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <chrono>
#include <filesystem>
#include <iostream>
#include <memory>
#include <string>

#include "methods.hpp"
#include "mpi_session.hpp"

#if defined(SIMSR_HAVE_MPI)
#include <simsr/mpi/batch_group.hpp>
#endif

namespace simsr::cli {

struct TrainArgs {
  std::string lr, hr, frames, out, neighbors, official_neighbors, checkpoint, resume, out_dir, contact;
  Index holdout = 4;
  Index eval_every = 1;  ///< evaluate the held-out frames every that many epochs (and after the last)
  interp::NetworkRecipe recipe;  ///< the library's defaults, the measured bunny recipe (network_recipe.hpp)
  bool quiet = false;
};

inline int train_cmd(const TrainArgs& a) {
  using clock = std::chrono::steady_clock;
  const auto t_start = clock::now();
  interp::UpsamplingProblem<> problem{data::read_lr_rest(a.lr), data::read_hr_rest(a.hr), {}, {}};
  nlohmann::ordered_json j;
  j["profile"] = a.recipe.profile;
  if (!a.official_neighbors.empty()) {
    problem.use(data::read_official_neighborhoods(a.official_neighbors, problem.num_lr(), problem.num_hr()));
    j["neighbors"] = "official files in " + a.official_neighbors;
  } else if (!a.neighbors.empty()) {
    problem.use(data::read_network_neighborhoods(a.neighbors, problem.num_lr(), problem.num_hr()));
    j["neighbors"] = a.neighbors;
  } else {
    j["neighbors"] = "computed (assignment + k-label Dijkstra; LR geodesic kNN)";
  }
  if (a.recipe.without_cu) j["neighbors"] = "Euclidean kNN (w/o CU)";
  const auto frames = data::read_paired_frames(a.frames, problem.num_lr(), problem.num_hr());
  const auto split = data::holdout_every(frames.num_frames(), a.holdout);
  const auto train = frames.select(split.train), test = frames.select(split.test);
  const auto train_displacements = data::displacements(train, problem.lr.V, problem.hr.V);
  const nn::NetworkConfig cfg = a.recipe.config(train_displacements);
  const auto held = data::displacements(test, problem.lr.V, problem.hr.V);
  j["displacement_scale"] = cfg.displacement_scale;

  interp::Learned<> net(cfg, a.recipe.seed);
  interp::prepare(exec::omp, net, problem, interp::Learned<>::neighborhoods_needed(cfg));  // geometry only: training follows
  double embedded_error = -1;
  if (test.num_frames() > 0) {  // the baseline to beat, on the same held-out frames
    interp::Embedded<> embedded;
    embedded_error = eval::run_method(exec::omp, embedded, problem, train, test).errors.statistics().mean;
  }
  const auto t_geo = clock::now();
  interp::NetworkTrainOptions o;
  o.trainer.seed = a.recipe.seed;
  o.trainer.progress = !a.quiet;
  const bool root = prints_results();
#if defined(SIMSR_HAVE_MPI)
  std::unique_ptr<mpi::MpiBatchGroup> group;
  if (const MpiSession* s = mpi_session(); s != nullptr && s->size() > 1) {
    group = std::make_unique<mpi::MpiBatchGroup>(*s->world());
    o.trainer.group = group.get();
  }
#endif
  o.trainer.lr_decay_epochs = a.recipe.lr_decay_epochs;
  if (test.num_frames() > 0) o.holdout = &held;
  o.trainer.holdout_every_epochs = a.eval_every;
  o.checkpoint = a.checkpoint;
  o.resume = a.resume;
  if (!a.contact.empty()) {
    if (!(cfg.w_contact > 0)) throw ArgumentError("--contact " + a.contact + " needs --w-contact > 0 (patches without a weight would be ignored)");
    o.contact = data::read_contact_patches(a.contact, problem.num_hr());
  } else if (cfg.w_contact > 0) {
    throw ArgumentError("--w-contact needs --contact FILE (the patches, e.g. the hr_lips.npz of simsr datagen --scenario face)");
  }
  net.train(exec::omp, train_displacements, o);
  const auto t_train = clock::now();
  if (!root) return 0;  // every rank holds the same network: rank 0 writes and prints
  net.save(a.out);

  const double diag = eval::bbox_diagonal(problem.hr.V);
  const auto& h = net.history();
  if (!a.out_dir.empty()) eval::write_training_history(a.out_dir, h, diag, embedded_error);
  const auto sec = [](auto d) { return std::chrono::duration<double>(d).count(); };
  j["model"] = a.out;
  j["parameters"] = net.network().store().num_parameters();
  j["train_frames"] = train.num_frames();
  j["holdout_frames"] = test.num_frames();
  j["epochs"] = net.epoch();
  j["steps"] = net.steps();
  j["batch_size"] = net.batch_size();
  j["ranks"] = mpi_session() ? mpi_session()->size() : 1;
  if (net.gathers() > 0) {  // data-parallel: what rank 0 received per optimizer step (the README's scaling model)
    j["gathers_per_step"] = double(net.gathers()) / double(std::max<std::int64_t>(1, net.steps()));
    j["bytes_received_per_step"] = double(net.bytes_received()) / double(std::max<std::int64_t>(1, net.steps()));
  }
  if (const auto* b = net.base_info()) j["residual_base"] = b->to_json();
  j["geometry_seconds"] = sec(t_geo - t_start);
  j["training_seconds"] = sec(t_train - t_geo);
  if (!h.empty()) {
    j["final_loss"] = h.back().loss;
    if (h.back().holdout_mean_error >= 0) {
      j["holdout_mean_error"] = h.back().holdout_mean_error;
      j["holdout_relative_mean_error"] = h.back().holdout_mean_error / diag;
      j["embedded_relative_mean_error"] = embedded_error / diag;
    }
  }
  std::cout << j.dump() << '\n';
  return 0;
}

inline void add_train(CLI::App& app, std::function<int()>& action) {
  auto* cmd = app.add_subcommand("train", "Train the super-resolution network on paired LR/HR frames; writes a self-contained model .npz");
  auto a = std::make_shared<TrainArgs>();
  cmd->add_option("--lr-rest", a->lr, "LR rest tet mesh (.msh .node/.ele .mesh, or OBJ with 4 triangles per tet)")->required();
  cmd->add_option("--hr-rest", a->hr, "HR rest surface")->required();
  cmd->add_option("--frames", a->frames, ".npz with lowres (F×N×3) and highres (F×M×3) absolute positions, optional frame ids")->required();
  cmd->add_option("--out", a->out, "output model .npz")->required();
  cmd->add_option("--neighbors", a->neighbors, "neighbourhoods from `simsr neighbors` (computed when absent)");
  cmd->add_option("--official-neighbors", a->official_neighbors, "folder with the authors' geo_dist_*.npy files (the bunny layout)");
  auto& r = a->recipe;
  cmd->add_option("--profile", r.profile, "official (default) | paper")->check(CLI::IsMember({"official", "paper"}));
  cmd->add_option("--epochs", r.epochs, "epochs (default: 60 official, about 17 minutes for the bunny on 2 cores; 10 paper)");
  cmd->add_option("--seed", r.seed, "seed of the initial weights and the shuffling (default 0)");
  cmd->add_option("--batch-size", r.batch_size, "frames per batch (default 8; the official code uses 32)");
  cmd->add_option("--lr", r.lr, "Adam learning rate (default 1e-3; the official code uses 2e-4)");
  cmd->add_option("--w-recon", r.w_recon, "weight of the L1 reconstruction term (official 10)");
  cmd->add_option("--w-zreg", r.w_zreg, "weight of the latent regularizer (official 2; paper: the ramp's end)");
  cmd->add_option("--w-fn", r.w_fn, "weight of the face-normal term (0.001)");
  cmd->add_option("--lr-decay-epochs", r.lr_decay_epochs, "halve the learning rate every that many epochs (default 12; 0: never)");
  cmd->add_option("--displacement-scale", r.displacement_scale,
                  "multiply normalized displacements by this (1: official; 0, the default: from the training frames, HR RMS 1)");
  cmd->add_option("--contact", a->contact, "contact patches of the HR surface (.npz with a, b: e.g. hr_lips.npz of simsr datagen --scenario face)");
  cmd->add_option("--w-contact", r.w_contact, "weight of the contact term (default 0: off)")->check(CLI::NonNegativeNumber);
  cmd->add_option("--contact-radius", r.contact_radius, "pairs closer than this at rest take part, and how far behind a triangle a vertex still counts (mesh units; default 0.005)")->check(CLI::PositiveNumber);
  cmd->add_option("--contact-margin", r.contact_margin, "clearance asked for (mesh units; default 2e-4)")->check(CLI::NonNegativeNumber);
  cmd->add_option("--knn", r.knn, "EdgeConv k (default 5)");
  cmd->add_option("--upk", r.up_k, "upsampling neighbours (default: 10 official, 20 paper)");
  cmd->add_option("--holdout-every", a->holdout, "frames f with f % n == 0 are held out and evaluated (default 4; 0: none)");
  cmd->add_option("--eval-every", a->eval_every, "evaluate the held-out frames every that many epochs and after the last (default 1; 0: never)")
      ->check(CLI::NonNegativeNumber);
  cmd->add_flag("--residual,!--no-residual", r.residual,
                "learn the correction of the Embedded interpolation, Δx = Embedded + network (default); --no-residual: the network alone");
  cmd->add_option("--residual-base", r.residual_base,
                  "what the residual adds to: embedded (default) or local_linear (fitted on the training frames)")
      ->check(CLI::IsMember({"embedded", "local_linear"}));
  cmd->add_flag("--without-fe", r.without_fe, "ablation w/o FE: h⁰ goes straight to the upsampling");
  cmd->add_flag("--without-cu", r.without_cu, "ablation w/o CU: fixed Euclidean neighbours with free learned weights");
  cmd->add_option("--checkpoint", a->checkpoint, "write a resumable checkpoint here after every epoch");
  cmd->add_option("--resume", a->resume, "continue from a checkpoint (same data and options)");
  cmd->add_option("--out-dir", a->out_dir, "write training_history.csv, training_loss.svg, holdout_error.svg here");
  cmd->add_flag("--quiet", a->quiet, "no progress line on stderr");
  cmd->callback([&action, a] { action = [a] { return train_cmd(*a); }; });
}

}  // namespace simsr::cli
