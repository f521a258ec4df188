// nn::ContactLoss (the lip-contact term, issue #12 item 7): the value on two facing grids against
// the closed form, the gradient against central differences on random penetrating shapes, seq ==
// omp bitwise, gradient descent on the term alone removes every penetration, and the term inside
// SuperResolutionLoss and the Trainer (mesh units, checkpoints, errors).
#include "gradient_check.hpp"
#include "network_fixture.hpp"

#include <simsr/nn/contact_loss.hpp>
#include <simsr/nn/trainer.hpp>

#include <cmath>
#include <filesystem>
#include <random>

using namespace simsr;
using nn::Matrix;

namespace {

/// Two facing square grids of n×n vertices and side `side`: patch b (rows 0..n²-1) at z = 0 with
/// outward normals +z (a body below it), patch a (rows n²..2n²-1) at z = gap, shifted by
/// (0.37, 0.21) cells, outward normals −z (a body above it).
struct Facing {
  Points<double> rest;
  ContactPatches patches;
  Index n = 0;
  double cell = 0, gap = 0, side = 0;
};

Facing facing_grids(Index n, double side, double gap) {
  Facing f;
  f.n = n;
  f.side = side;
  f.gap = gap;
  f.cell = side / double(n - 1);
  f.rest.resize(2 * n * n, 3);
  for (Index j = 0; j < n; ++j)
    for (Index i = 0; i < n; ++i) {
      f.rest.row(j * n + i) << double(i) * f.cell, double(j) * f.cell, 0.0;
      f.rest.row(n * n + j * n + i) << (double(i) + 0.37) * f.cell, (double(j) + 0.21) * f.cell, gap;
    }
  const Index cells = (n - 1) * (n - 1);
  f.patches.a.resize(2 * cells, 3);
  f.patches.b.resize(2 * cells, 3);
  Index t = 0;
  for (Index j = 0; j + 1 < n; ++j)
    for (Index i = 0; i + 1 < n; ++i, t += 2) {
      const VIndex v00 = VIndex(j * n + i), v10 = v00 + 1, v01 = VIndex(v00 + n), v11 = v01 + 1;
      f.patches.b.row(t) << v00, v10, v11;  // counter-clockwise seen from +z: normal +z
      f.patches.b.row(t + 1) << v00, v11, v01;
      const VIndex o = VIndex(n * n);
      f.patches.a.row(t) << o + v00, o + v11, o + v10;  // clockwise: normal −z
      f.patches.a.row(t + 1) << o + v00, o + v01, o + v11;
    }
  return f;
}

/// Vertices of the grids whose (x, y) lies strictly inside the other grid's square: the ones that
/// project into one of its triangles.
Index overlapping_vertices(const Facing& f) {
  Index k = 0;
  const double lo_a[2] = {0.37 * f.cell, 0.21 * f.cell};
  for (Index v = 0; v < f.rest.rows(); ++v) {
    const bool in_a = v >= f.n * f.n;
    const double x = f.rest(v, 0), y = f.rest(v, 1);
    const double x0 = in_a ? 0.0 : lo_a[0], y0 = in_a ? 0.0 : lo_a[1];
    k += x > x0 && x < x0 + f.side && y > y0 && y < y0 + f.side;
  }
  return k;
}

/// One item: the upper grid moved down by `drop` (z), the lower one still.
Matrix<double> drop_upper(const Facing& f, double drop) {
  Matrix<double> pred = Matrix<double>::Zero(f.rest.rows(), 3);
  pred.bottomRows(f.n * f.n).col(2).setConstant(-drop);
  return pred;
}

}  // namespace

TEST_CASE("nn::ContactLoss: two facing grids give the closed form (m − s)² per overlapping vertex, penetrations counted") {
  for (const double gap : {1e-3, 0.25, 3.0}) {
    const Facing f = facing_grids(7, 6 * gap, gap);
    const double margin = 0.3 * gap;  // below half the rest gap: every pair asks for it
    nn::ContactLoss<double> loss(f.rest, f.patches, 1.5 * gap, margin);
    const Index k = overlapping_vertices(f);
    REQUIRE(k > 40);
    CAPTURE(gap);
    // apart: nothing active
    CHECK(loss.value_and_gradient(exec::seq, drop_upper(f, 0.5 * gap)) == 0.0);
    CHECK(loss.active() == 0);
    // within the margin (s = 0.2 gap): each overlapping vertex adds (0.1 gap)²
    CHECK(loss.value_and_gradient(exec::seq, drop_upper(f, 0.8 * gap)) == doctest::Approx(double(k) * std::pow(0.1 * gap, 2)).epsilon(1e-9));
    CHECK(loss.active() == k);
    CHECK(loss.penetrating() == 0);
    // through (s = −0.3 gap): (0.6 gap)² each, all penetrating
    CHECK(loss.value_and_gradient(exec::seq, drop_upper(f, 1.3 * gap)) == doctest::Approx(double(k) * std::pow(0.6 * gap, 2)).epsilon(1e-9));
    CHECK(loss.penetrating() == k);
    // beyond the radius (s = −1.6 gap): ignored, as the other side of a thin body would be
    CHECK(loss.value_and_gradient(exec::seq, drop_upper(f, 2.6 * gap)) == 0.0);
    // a batch of two items is their mean
    Matrix<double> two(2 * f.rest.rows(), 3);
    two.topRows(f.rest.rows()) = drop_upper(f, 0.8 * gap);
    two.bottomRows(f.rest.rows()) = drop_upper(f, 1.3 * gap);
    CHECK(loss.value_and_gradient(exec::seq, two) == doctest::Approx(0.5 * double(k) * (std::pow(0.1 * gap, 2) + std::pow(0.6 * gap, 2))).epsilon(1e-9));
  }
  {  // a rest gap below twice the margin: each pair asks for half its rest distance only
    const Facing f = facing_grids(5, 4.0, 1.0);
    nn::ContactLoss<double> loss(f.rest, f.patches, 1.5, 0.9);
    CHECK(loss.value_and_gradient(exec::seq, drop_upper(f, 0.0)) == 0.0);  // at rest: nothing pushes
    CHECK(loss.value_and_gradient(exec::seq, drop_upper(f, 0.6)) == doctest::Approx(double(overlapping_vertices(f)) * 0.01).epsilon(1e-9));
  }
}

TEST_CASE("nn::ContactLoss: the gradient matches central differences on random penetrating shapes (the normal's rotation included)" * doctest::test_suite("single-threaded")) {
  std::mt19937_64 rng(17);
  Index checked = 0, kinks = 0;
  for (int trial = 0; trial < 25; ++trial) {
    Facing f = facing_grids(5, 4.0, 1.0);
    f.rest += 0.15 * test::random_matrix(rng, f.rest.rows(), 3);  // not flat, not aligned
    nn::ContactLoss<double> loss(f.rest, f.patches, 2.0, 0.3);
    const Index B = 2;
    Matrix<double> pred(B * f.rest.rows(), 3);
    for (Index b = 0; b < B; ++b) pred.middleRows(b * f.rest.rows(), f.rest.rows()) = drop_upper(f, 1.2) + 0.25 * test::random_matrix(rng, f.rest.rows(), 3);
    Matrix<double> grad = Matrix<double>::Zero(pred.rows(), 3);
    const double scale = 0.7;
    const double value = loss.value_and_gradient(exec::seq, pred, &grad, scale);
    const Index active = loss.active();
    REQUIRE(active > 10);
    REQUIRE(loss.penetrating() > 0);
    (void)value;
    const double h = 1e-6;
    double worst = 0, largest = 0;
    for (Index i = 0; i < pred.size(); ++i) {
      Matrix<double> p = pred;
      p.data()[i] += h;
      const double up = loss.value_and_gradient(exec::seq, p);
      const Index active_up = loss.active();
      p.data()[i] -= 2 * h;
      const double down = loss.value_and_gradient(exec::seq, p);
      if (active_up != active || loss.active() != active) {  // a foot crossing an edge within ±h: no derivative there
        ++kinks;
        continue;
      }
      const double numeric = scale * (up - down) / (2 * h);
      worst = std::max(worst, std::abs(numeric - grad.data()[i]));
      largest = std::max(largest, std::abs(grad.data()[i]));
      ++checked;
    }
    CAPTURE(trial);
    CHECK(largest > 0.1);
    CHECK(worst <= 1e-6 * largest);
  }
  CHECK(kinks <= checked / 100);  // a kink within 1e-6 is rare
}

TEST_CASE("nn::ContactLoss: seq == omp bitwise, the gradient is added to what d_pred holds") {
  std::mt19937_64 rng(5);
  Facing f = facing_grids(6, 5.0, 1.0);
  f.rest += 0.1 * test::random_matrix(rng, f.rest.rows(), 3);
  nn::ContactLoss<float> a(f.rest, f.patches, 2.0, 0.2), b(f.rest, f.patches, 2.0, 0.2);
  const Index B = 5;
  Matrix<float> pred(B * f.rest.rows(), 3);
  for (Index i = 0; i < B; ++i) pred.middleRows(i * f.rest.rows(), f.rest.rows()) = (drop_upper(f, 1.1) + 0.3 * test::random_matrix(rng, f.rest.rows(), 3)).cast<float>();
  const Matrix<float> start = test::random_matrix(rng, pred.rows(), 3).cast<float>();
  Matrix<float> gs = start, go = start, g0 = Matrix<float>::Zero(pred.rows(), 3);
  const double vs = a.value_and_gradient(exec::seq, pred, &gs, 2.0);
  const double vo = b.value_and_gradient(exec::omp, pred, &go, 2.0);
  CHECK(vs == vo);
  CHECK(gs == go);
  CHECK(a.penetrating() == b.penetrating());
  a.value_and_gradient(exec::seq, pred, &g0, 2.0);
  CHECK((gs - start - g0).cwiseAbs().maxCoeff() <= 1e-6f * (1 + g0.cwiseAbs().maxCoeff()));
}

TEST_CASE("nn::ContactLoss: gradient descent on the term alone separates grids pushed through each other") {
  std::mt19937_64 rng(8);
  Facing f = facing_grids(6, 5.0, 1.0);
  f.rest += 0.05 * test::random_matrix(rng, f.rest.rows(), 3);
  nn::ContactLoss<double> loss(f.rest, f.patches, 2.0, 0.1);
  Matrix<double> pred = drop_upper(f, 1.4) + 0.1 * test::random_matrix(rng, f.rest.rows(), 3);
  loss.value_and_gradient(exec::seq, pred);
  REQUIRE(loss.penetrating() > 20);
  Matrix<double> g(pred.rows(), 3);
  for (int step = 0; step < 400; ++step) {
    g.setZero();
    loss.value_and_gradient(exec::seq, pred, &g);
    pred -= 0.05 * g;
  }
  CHECK(loss.value_and_gradient(exec::seq, pred) < 1e-4);
  CHECK(loss.penetrating() == 0);
}

TEST_CASE("nn::ContactLoss: candidates are pairs near at rest with the vertex outside; bad patches are named") {
  const Facing f = facing_grids(4, 3.0, 1.0);
  nn::ContactLoss<double> near(f.rest, f.patches, 1.01, 0.1), far(f.rest, f.patches, 0.5, 0.1);
  CHECK(far.pairs().empty());  // the grids are 1 apart
  REQUIRE(!near.pairs().empty());
  for (const auto& p : near.pairs()) {
    const bool a_vertex = p.vertex >= f.n * f.n;
    for (Index c : p.tri) CHECK((c >= f.n * f.n) != a_vertex);  // a vertex against the other patch's triangle
    CHECK(p.margin == doctest::Approx(0.1));
  }
  {  // reversed orientation of b: the upper vertices lie behind its triangles and take no part
    ContactPatches flipped = f.patches;
    flipped.b.col(1).swap(flipped.b.col(2));
    nn::ContactLoss<double> l(f.rest, flipped, 1.01, 0.1);
    for (const auto& p : l.pairs()) CHECK(p.vertex < f.n * f.n);
  }
  auto bad = f.patches;
  bad.a(2, 1) = VIndex(f.rest.rows());
  CHECK_THROWS_WITH_AS(nn::ContactLoss<double>(f.rest, bad, 1, 0.1), doctest::Contains("patch a triangle 2 has vertex 32 outside [0, 32)"), ArgumentError);
  bad = f.patches;
  bad.a(0, 0) = f.patches.b(3, 2);
  CHECK_THROWS_WITH_AS(nn::ContactLoss<double>(f.rest, bad, 1, 0.1), doctest::Contains("belongs to both contact patches"), ArgumentError);
  CHECK_THROWS_WITH_AS(nn::ContactLoss<double>(f.rest, ContactPatches{f.patches.a, {}}, 1, 0.1), doctest::Contains("at least one triangle"), ArgumentError);
  CHECK_THROWS_AS(nn::ContactLoss<double>(f.rest, f.patches, 0, 0.1), ArgumentError);
  CHECK_THROWS_AS(nn::ContactLoss<double>(f.rest, f.patches, 1, -0.1), ArgumentError);
  nn::ContactLoss<double> l(f.rest, f.patches, 1, 0.1);
  CHECK_THROWS_AS(l.value_and_gradient(exec::seq, Matrix<double>::Zero(f.rest.rows() + 1, 3)), ShapeError);
  Matrix<double> small(3, 3);
  CHECK_THROWS_AS(l.value_and_gradient(exec::seq, Matrix<double>::Zero(f.rest.rows(), 3), &small), ShapeError);
}

TEST_CASE("nn::SuperResolutionLoss: the contact term works in mesh units whatever the normalization, and is refused half-configured") {
  const Facing f = facing_grids(5, 0.006, 1e-3);  // a millimetre gap, in metres
  nn::NetworkConfig cfg = nn::NetworkConfig::official();
  cfg.displacement_scale = 3.0;
  cfg.w_contact = 0.5;
  cfg.contact_radius = 1.5e-3;
  cfg.contact_margin = 0.3e-3;
  cfg.w_fn = 0;
  const Tris faces = f.patches.a;  // any faces for the face-normal term (off)
  const Matrix<double> rest_n = nn::normalize_positions<double>(f.rest, cfg.norm_mean, cfg.norm_std);
  nn::SuperResolutionLoss<double> with(cfg, rest_n, faces);
  with.set_contact(rest_n, f.patches);
  nn::NetworkConfig off = cfg;
  off.w_contact = 0;
  nn::SuperResolutionLoss<double> without(off, rest_n, faces);
  const double unit = cfg.displacement_unit();  // metres per network unit
  const Matrix<double> pred = drop_upper(f, 1.3e-3) / unit, target = Matrix<double>::Zero(pred.rows(), 3);
  const Matrix<double> z = Matrix<double>::Zero(4, cfg.latent_dim());
  Matrix<double> d_with, d_without, d_z;
  const auto tw = with.evaluate(exec::seq, pred, target, z, 0, &d_with, &d_z);
  const auto to = without.evaluate(exec::seq, pred, target, z, 0, &d_without, &d_z);
  const double gap_network_units = (0.3e-3 - (1e-3 - 1.3e-3)) / unit;
  CHECK(tw.contact == doctest::Approx(0.5 * double(overlapping_vertices(f)) * gap_network_units * gap_network_units).epsilon(1e-9));
  CHECK(tw.penetrating == overlapping_vertices(f));
  CHECK(tw.total == doctest::Approx(to.total + tw.contact).epsilon(1e-12));
  CHECK(to.contact == 0);
  // the term pushes the upper grid up (+z in network units) where it penetrates
  CHECK((d_with - d_without).bottomRows(f.n * f.n).col(2).sum() < 0);
  CHECK_THROWS_WITH_AS(without.set_contact(rest_n, f.patches), doctest::Contains("w_contact is 0"), ArgumentError);
  nn::SuperResolutionLoss<double> unset(cfg, rest_n, faces);
  CHECK_THROWS_WITH_AS(unset.evaluate(exec::seq, pred, target, z, 0, &d_with, &d_z), doctest::Contains("no contact patches"), ArgumentError);
  nn::NetworkConfig no_radius = cfg;
  no_radius.contact_radius = 0;
  CHECK_THROWS_WITH_AS(no_radius.validate(), doctest::Contains("contact_radius > 0"), ArgumentError);
  // the fields survive the model file's JSON, and a config without them reads as off
  const auto back = nn::NetworkConfig::from_json(cfg.to_json());
  CHECK(back.w_contact == 0.5);
  CHECK(back.contact_radius == 1.5e-3);
  CHECK(back.contact_margin == 0.3e-3);
  auto older = cfg.to_json();
  older.erase("w_contact");
  older.erase("contact_radius");
  older.erase("contact_margin");
  CHECK(nn::NetworkConfig::from_json(older).w_contact == 0);
}

TEST_CASE("nn::Trainer: the contact term trains, is reported per epoch, and a checkpoint of other patches is refused") {
  std::mt19937_64 rng(3);
  nn::NetworkConfig cfg = test::tiny_config(nn::NetworkConfig::official());
  cfg.batch_size = 2;
  cfg.w_contact = 1.0;
  cfg.contact_radius = 2.0;
  cfg.contact_margin = 0.05;
  cfg.norm_mean = 0;
  cfg.norm_std = 1;
  const Facing f = facing_grids(4, 3.0, 0.2);  // the HR surface: two grids
  const Index N = 12, M = f.rest.rows();
  nn::NetworkGeometry geo = test::small_network_geometry(rng, N, M, cfg);
  geo.hr_rest = f.rest;
  nn::TrainingFrames<double> frames;
  frames.n = N, frames.m = M, frames.frames = 4;
  frames.ldx = test::random_matrix(rng, 4 * N, 3, -0.1, 0.1);
  frames.hdx = Matrix<double>::Zero(4 * M, 3);
  for (Index i = 0; i < 4; ++i) {
    frames.hdx.middleRows(i * M, M) = drop_upper(f, 0.4);  // targets that push the grids through each other
    frames.ids.push_back(i);
  }
  const Tris faces = f.patches.b;
  const auto dir = std::filesystem::path(SIMSR_TEST_TMP_DIR) / "contact_trainer";
  std::filesystem::create_directories(dir);
  nn::ModelData md{cfg, geo, Tets::Zero(1, 4), faces};
  md.lr_tets.row(0) << 0, 1, 2, 3;
  const nn::TrainerOptions opts{.epochs = 12, .seed = 4, .progress = false, .on_epoch = {}};
  {
    nn::Rng init(1);
    nn::SuperResolutionNet<double> net(cfg, geo, init);
    nn::Trainer<double> tr(net, faces, frames, opts);
    CHECK_THROWS_WITH_AS(tr.run_epoch(exec::seq), doctest::Contains("no contact patches"), ArgumentError);
  }
  nn::Rng init(1);
  nn::SuperResolutionNet<double> net(cfg, geo, init);
  nn::Trainer<double> tr(net, faces, frames, opts);
  tr.set_contact(f.patches);
  tr.save_checkpoint(dir / "ckpt.npz", md);
  tr.run(exec::seq);
  REQUIRE(tr.history().size() == 12);
  double most = 0;
  for (const auto& r : tr.history()) {
    CHECK(r.loss == doctest::Approx(r.recon + r.z_reg + r.face_normals + r.contact).epsilon(1e-12));
    most = std::max(most, r.contact);
  }
  CHECK(most > 0);  // the targets push the grids through each other: the predictions fitted to them meet the term
  CHECK(tr.data_json().contains("contact_fingerprint"));
  {  // other patches: refused, naming the contact fingerprint
    nn::Rng again(1);
    nn::SuperResolutionNet<double> net2(cfg, geo, again);
    nn::Trainer<double> tr2(net2, faces, frames, opts);
    ContactPatches fewer{f.patches.a.topRows(4), f.patches.b};
    tr2.set_contact(fewer);
    CHECK_THROWS_WITH_AS(tr2.load_checkpoint(dir / "ckpt.npz"), doctest::Contains("contact_fingerprint"), ArgumentError);
  }
}
