#pragma once
/// \file
/// The data-parallel training tests' problem and comparison (tests/nn/test_batch_split.cpp with
/// threads, tests/mpi/test_train.cpp over MPI): a small network and frames, what a run leaves
/// (weights, buffers, Adam's moments, the losses), and a bit-for-bit comparison of two runs.

#include <doctest/doctest.h>

#include <simsr/nn/trainer.hpp>

#include <cstring>
#include <string>
#include <vector>

#include "gradient_check.hpp"
#include "network_fixture.hpp"

namespace simsr::test {

using nn::Matrix;

template <class S>
struct Problem {
  nn::NetworkConfig cfg;
  nn::NetworkGeometry geo;
  Tris faces;
  nn::TrainingFrames<S> frames;
  nn::TrainingFrames<S> holdout;  ///< 2 frames (shared by 2 ranks; 3 ranks evaluate both each)
};

/// A small problem: HR displacements a smooth function of the LR ones, F frames.
template <class S>
Problem<S> make_problem(nn::NetworkConfig base, std::uint64_t seed, Index F, Index batch) {
  Problem<S> p;
  p.cfg = test::tiny_config(std::move(base));
  p.cfg.batch_size = batch;
  p.cfg.lr = 3e-3;
  std::mt19937_64 rng(seed);
  const Index N = 20, M = 24;
  p.geo = test::small_network_geometry(rng, N, M, p.cfg);
  p.faces.resize(16, 3);
  for (Index f = 0; f < p.faces.rows(); ++f) p.faces.row(f) << VIndex(f), VIndex((f + 3) % M), VIndex((f + 7) % M);
  auto& d = p.frames;
  d.n = N, d.m = M, d.frames = F;
  const Matrix<double> l = test::random_matrix(rng, F * N, 3, -0.3, 0.3);
  d.ldx = l.cast<S>();
  d.hdx.resize(F * M, 3);
  for (Index f = 0; f < F; ++f)
    for (Index j = 0; j < M; ++j) {
      Eigen::RowVector3d s = Eigen::RowVector3d::Zero();
      for (Index i = 0; i < 3; ++i) s += l.row(f * N + p.geo.up_indices(j, i));
      d.hdx.row(f * M + j) = (0.5 * s + 0.1 * s.cwiseAbs2()).cast<S>();
    }
  for (Index f = 0; f < F; ++f) d.ids.push_back(f);
  p.holdout = d;
  p.holdout.frames = 2;
  p.holdout.ldx = d.ldx.topRows(2 * N);
  p.holdout.hdx = d.hdx.topRows(2 * M) * S(1.1);
  p.holdout.ids = {0, 1};
  return p;
}

/// What a run leaves: weights and buffers, Adam's moments, the epochs' losses, flat.
template <class S>
struct RunState {
  std::vector<S> values, buffers, exp_avg, exp_avg_sq;
  std::vector<double> losses;
};

template <class S>
RunState<S> state_of(nn::SuperResolutionNet<S>& net, nn::Trainer<S>& tr) {
  RunState<S> r;
  const auto v = net.store().values(), b = net.store().buffers();
  r.values.assign(v.data(), v.data() + v.size());
  r.buffers.assign(b.data(), b.data() + b.size());
  const auto& m = tr.optimizer().state().exp_avg;
  const auto& q = tr.optimizer().state().exp_avg_sq;
  r.exp_avg.assign(m.data(), m.data() + m.size());
  r.exp_avg_sq.assign(q.data(), q.data() + q.size());
  for (const auto& e : tr.history()) r.losses.insert(r.losses.end(), {e.loss, e.recon, e.z_reg, e.face_normals, e.holdout_mean_error});
  return r;
}

template <class T>
bool same_bits(const std::vector<T>& a, const std::vector<T>& b) {
  return a.size() == b.size() && (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(T)) == 0);
}
template <class S>
void check_same(const RunState<S>& a, const RunState<S>& b, const std::string& what) {
  INFO(what);
  CHECK(same_bits(a.values, b.values));
  CHECK(same_bits(a.buffers, b.buffers));
  CHECK(same_bits(a.exp_avg, b.exp_avg));
  CHECK(same_bits(a.exp_avg_sq, b.exp_avg_sq));
  CHECK(same_bits(a.losses, b.losses));
  CHECK(!a.values.empty());
}

inline nn::TrainerOptions options(Index epochs, nn::BatchGroup* group) {
  nn::TrainerOptions o;
  o.epochs = epochs;
  o.seed = 11;
  o.progress = false;
  o.group = group;
  return o;
}

}  // namespace simsr::test
