// Detail synthesis on a reduced SHEET dataset (issue #14 items 2 and 5): the dataset read back
// with its obstacles, training that fits, a killed training run resuming bitwise, another run's
// checkpoint refused, and the evaluation's figures checked against a direct computation.
#include <doctest/doctest.h>

#include <simsr/shell/cloth_datagen.hpp>
#include <simsr/mesh/generators.hpp>
#include <simsr/shell/cloth_synthesis.hpp>
#include <simsr/shell/cloth_upsampling.hpp>
#include <simsr/interp/learned.hpp>
#include <simsr/interp/local_linear.hpp>
#include <simsr/interp/network_recipe.hpp>

#include <numbers>

#include "../support/error_of.hpp"
#include "../support/scratch_dir.hpp"

namespace shell_test_cloth_synthesis {

using namespace simsr;
using namespace simsr::shell;

DetailSynthesisOptions small_net() {
  DetailSynthesisOptions o;
  o.codec = {.channels = 6, .latent = 8};
  o.transformer = {.latent = 8, .d_model = 16, .feed_forward = 32, .heads = 8, .blocks = 1, .frames = 3};
  o.lr_step = 1000;
  return o;
}

const std::filesystem::path& dataset() {
  static const test::ScratchDir dir("simsr_test_cloth_synthesis");
  static const bool made = [] {
    ClothDatagenOptions o;
    o.size = {3, 1};  // 16 / 49 vertices
    o.sequences = 5;  // the 5th held out
    o.extra_seconds = 0;
    o.settle_frames = 5;
    o.simulation.frame_time = 0.1;
    generate_cloth_data(exec::omp, ClothDataset::sheet, dir.path, o);
    return true;
  }();
  (void)made;
  return dir.path;
}

TEST_CASE("read_cloth_data: the pair, the split and every frame; the obstacle at a frame's end touches the simulated cloth") {
  const ClothData d = read_cloth_data(dataset());
  CHECK(d.num_coarse() == 16);
  CHECK(d.num_fine() == 49);
  REQUIRE(d.sequences.size() == 5);
  CHECK(d.sequences[4].test);
  CHECK_FALSE(d.sequences[0].test);
  CHECK(read_cloth_data(dataset(), "test").sequences.size() == 1);
  for (const auto& s : d.sequences) {
    CHECK(s.fine.size() == s.coarse.size());
    // the simulation kept the fine cloth outside the obstacle, and touched it: the rebuilt
    // obstacle (time (f+1)·dt) must agree to the contact's few millimetres
    double closest = 1e9;
    for (Index f = 0; f < s.num_frames(); ++f)
      d.with_obstacle(s.index, f, [&](const auto& o) {
        for (Index i = 0; i < d.num_fine(); ++i) closest = std::min(closest, o.distance(Vec3<>(s.fine[std::size_t(f)].row(i).transpose())));
      });
    CHECK(closest > -0.005);
    CHECK(closest < 0.02);
  }
  // one frame later the obstacle would be inside the cloth: the check above can tell the timing
  double later = 1e9;
  for (const auto& s : d.sequences)
    for (Index f = 0; f < s.num_frames(); ++f) {
      const auto o = d.sheet[std::size_t(s.index)].obstacle_at(double(f + 2) * d.frame_time);
      for (Index i = 0; i < d.num_fine(); ++i) later = std::min(later, o.distance(Vec3<>(s.fine[std::size_t(f)].row(i).transpose())));
    }
  CHECK(later < -0.01);
  test::ScratchDir empty("simsr_test_cloth_synthesis_empty");
  CHECK(test::typed_error_of<ParseError>([&] { read_cloth_data(empty.path); }).find("cloth_data.json") != std::string::npos);
}

/// The scale study's pairing at a reduced size: a 2-cell coarse sheet (9 vertices) beside
/// dataset()'s fine sheet (3 cells, Loop once: 49), its fine frames taken from dataset().
const std::filesystem::path& coarser_dataset() {
  static const test::ScratchDir dir("simsr_test_cloth_synthesis_coarser");
  static const bool made = [] {
    ClothDatagenOptions o;
    o.size = {2, 1, 3};
    o.sequences = 5;
    o.extra_seconds = 0;
    o.settle_frames = 5;
    o.simulation.frame_time = 0.1;
    o.fine_frames_from = dataset();
    generate_cloth_data(exec::omp, ClothDataset::sheet, dir.path, o);
    return true;
  }();
  (void)made;
  return dir.path;
}

/// RMS distance to the fine simulation of sequence t's subdivided coarse frames' features decoded
/// with the pins where the coarse frames have them, computed here from the parts.
double decoded_subdivided_rmse(const ClothSynthesis<>& run, const ClothData& d, const ClothSequenceFrames& t) {
  double sum = 0;
  TsAcapState<double> state;
  for (Index f = 0; f < t.num_frames(); ++f) {
    Points<> pins(d.pair.pinned.size(), 3);
    for (Index p = 0; p < pins.rows(); ++p) pins.row(p) = t.coarse[std::size_t(f)].row(d.pair.pinned[p]);
    const Points<> sub = d.pair.subdivision * t.coarse[std::size_t(f)];
    sum += (run.fine_acap().decode_anchored(exec::seq, run.fine_acap().encode(exec::seq, sub, state), pins) - t.fine[std::size_t(f)]).squaredNorm();
  }
  return std::sqrt(sum / double(t.num_frames() * d.num_fine()));
}

TEST_CASE("ClothSynthesis, residual fine target: a network whose residual is zero gives back the subdivided mesh's features decoded") {
  const ClothData d = read_cloth_data(dataset());
  // the same on the scale study's pairing: a coarser sheet of its own, the baseline map resampled
  const ClothData coarser = read_cloth_data(coarser_dataset());
  REQUIRE(coarser.num_coarse() == 9);
  REQUIRE(coarser.num_fine() == 49);
  CHECK(coarser.sequences[4].fine == d.sequences[4].fine);
  CHECK((coarser.pair.fine_pinned.array() == d.pair.pinned.array()).all());
  for (const ClothData* data : {&d, &coarser}) {
    for (const FineTarget target : {FineTarget::residual, FineTarget::features}) {
      if (data == &coarser && target == FineTarget::features) continue;
      const ClothData& e = *data;
      const auto& t = e.sequences[4];
      CAPTURE(e.num_coarse());
      CAPTURE(fine_target_name(target));
      DetailSynthesisOptions o = small_net();
      o.fine_target = target;
      ClothSynthesis run(exec::seq, e, o, 5);
      CHECK(run.residual() == (target == FineTarget::residual));
      // the decoder's last convolution made constant: its output is the normalized zero residual
      auto& net = run.network();
      auto& store = net.store();
      for (const char* w : {"fine_dec.conv2.point.weight", "fine_dec.conv2.neighbor.weight"})
        for (float& v : store.values(store.at(w))) v = 0;
      const auto bias = store.values(store.at("fine_dec.conv2.point.bias"));
      for (Index c = 0; c < 9; ++c) bias[std::size_t(c)] = float(-net.fine_scaling().mean[c] / net.fine_scaling().scale[c]);
      std::vector<Points<>> raw;
      run.synthesize(exec::seq, 4, nullptr, nullptr, &raw);
      const double expected = decoded_subdivided_rmse(run, e, t);
      double sum = 0;
      for (Index f = 0; f < t.num_frames(); ++f) sum += (raw[std::size_t(f)] - t.fine[std::size_t(f)]).squaredNorm();
      const double synthesized = std::sqrt(sum / double(t.num_frames() * e.num_fine()));
      if (target == FineTarget::residual) {
        CHECK(synthesized == doctest::Approx(expected).epsilon(1e-5));  // the residual passes through float
      } else {
        // the same zero output as features is a flat rotation-free sheet, far from the subdivided mesh
        CHECK(std::abs(synthesized - expected) > 0.1 * expected);
      }
    }
  }
  // a model of one fine target is refused by a network of the other
  test::ScratchDir dir("simsr_test_cloth_synthesis_target");
  std::filesystem::create_directories(dir.path);
  DetailSynthesisOptions o = small_net();
  ClothSynthesis run(exec::seq, d, o, 5);
  run.network().save(dir.path / "model.npz");
  CHECK(DetailSynthesisNet<float>::saved_options(dir.path / "model.npz").fine_target == FineTarget::residual);
  CHECK(DetailSynthesisNet<float>::saved_options(dir.path / "model.npz").residual_lift == ResidualLift::nearest);
  o.fine_target = FineTarget::features;
  DetailSynthesisNet<float> other(vertex_adjacency(d.pair.coarse.F, 16), vertex_adjacency(d.pair.fine.F, 49), o, 1);
  CHECK(test::typed_error_of<ArgumentError>([&] { other.load(dir.path / "model.npz"); }).find("'residual'") != std::string::npos);
  CHECK(test::typed_error_of<ArgumentError>([] { parse_fine_target("residuals"); }).find("residuals") != std::string::npos);
  CHECK(test::typed_error_of<ArgumentError>([] { parse_residual_lift("closest"); }).find("closest") != std::string::npos);
}

TEST_CASE("ClothSynthesis, residual lift: the trained residual's rotations are the forms nearest the subdivided mesh's; 'own' keeps the fine ones") {
  const ClothData d = read_cloth_data(dataset());
  const auto& s = d.sequences[0];
  REQUIRE(!s.test);
  DetailSynthesisOptions o = small_net();
  ClothSynthesis nearest(exec::seq, d, o, 5);
  o.residual_lift = ResidualLift::own;
  ClothSynthesis own(exec::seq, d, o, 5);
  // both count the same residuals beyond π as lifted alone; nearest trains on no more of them
  CHECK(nearest.feature_jumps().residual_own == own.feature_jumps().residual_own);
  CHECK(own.feature_jumps().residual_trained == own.feature_jumps().residual_own);
  CHECK(nearest.feature_jumps().residual_trained <= nearest.feature_jumps().residual_own);
  Index train_frames = 0;
  for (const auto& q : d.sequences) train_frames += q.test ? 0 : q.num_frames();
  CHECK(nearest.feature_jumps().residual_vertex_frames == train_frames * 49);
  // the two runs are different trainings: one's checkpoint is refused by the other
  const ClothTrainingOptions t{.epochs = 1, .batch = 8, .seed = 1, .checkpoint = {}};
  CHECK(nearest.fingerprint(t) != own.fingerprint(t));
  // the lift itself, on a frame whose fine features are turned by 2π at every third vertex (the
  // same rotations in other forms, as another run of the integer steps could have left them):
  // it gives back the forms nearest the subdivided frame's whichever forms the fine side came in
  TsAcapState<double> fs, bs;
  const TsAcapFeatures<double> fine = nearest.fine_acap().encode(exec::seq, s.fine[0], fs);
  const TsAcapFeatures<double> base = nearest.fine_acap().encode(exec::seq, nearest.subdivided({s.coarse[0]})[0], bs);
  TsAcapFeatures<double> turned = fine;
  for (Index i = 0; i < turned.rows(); i += 3) {
    const Vec3<> rho = turned.row(i).head<3>().transpose();
    const Vec3<> u = rho.norm() > 0 ? Vec3<>(rho.normalized()) : Vec3<>(0, 0, 1);
    turned.row(i).head<3>() = (rho + 2 * std::numbers::pi * u).transpose();
  }
  TsAcapFeatures<double> a = fine, b = turned;
  lift_rotations_toward(a, base);
  CHECK(lift_rotations_toward(b, base) >= (turned.rows() + 2) / 3);
  CHECK((a - b).cwiseAbs().maxCoeff() < 1e-9);
  CHECK(FeatureJumps::beyond_pi(b, base) <= FeatureJumps::beyond_pi(turned, base));
  CHECK(FeatureJumps::beyond_pi(b, base) == 0);  // a sheet's two simulations turn alike here
}

TEST_CASE("ClothSynthesis: training lowers the loss; a killed run resumes bitwise; another run is refused; the evaluation's figures") {
  const ClothData d = read_cloth_data(dataset());
  test::ScratchDir state("simsr_test_cloth_synthesis_state");
  const auto ckpt = state.path / "train.npz";
  DetailSynthesisOptions net;
  net.lr_step = 1000;

  ClothSynthesis whole(exec::seq, d, net, 3);
  const auto h = whole.train(exec::seq, {.epochs = 12, .batch = 8, .seed = 1, .checkpoint = {}});
  REQUIRE(h.size() == 12);
  CHECK(h.back().loss.synthesis < 0.6 * h.front().loss.synthesis);
  CHECK(h.back().loss.reconstruction < 0.6 * h.front().loss.reconstruction);

  ClothSynthesis killed(exec::seq, d, net, 3);
  killed.train(exec::seq, {.epochs = 6, .batch = 8, .checkpoint = ckpt});
  ClothSynthesis resumed(exec::seq, d, net, 3);
  const auto hr = resumed.train(exec::seq, {.epochs = 12, .batch = 8, .checkpoint = ckpt});
  REQUIRE(hr.size() == 12);
  CHECK(hr.back().loss.synthesis == h.back().loss.synthesis);
  CHECK(resumed.network().store().values() == whole.network().store().values());
  ClothSynthesis other(exec::seq, d, net, 3);
  CHECK(test::typed_error_of<ArgumentError>([&] { other.train(exec::seq, {.epochs = 12, .batch = 4, .checkpoint = ckpt}); }).find("another run") !=
        std::string::npos);

  // the evaluation's figures are the held-out sequence's, as computed here from synthesize()
  const ClothEvaluation ev = whole.evaluate(exec::seq);
  REQUIRE(ev.sequences.size() == 1);
  const auto& t = d.sequences[4];
  CHECK(ev.frames == t.num_frames());
  std::vector<Points<>> raw;
  ClothSequenceEvaluation e;
  const auto refined = whole.synthesize(exec::seq, 4, nullptr, &e, &raw);
  double a = 0, b = 0, c = 0, fl = 0;
  TsAcapState<double> truth_state;
  for (Index f = 0; f < t.num_frames(); ++f) {
    Points<> pins(d.pair.pinned.size(), 3);
    for (Index p = 0; p < pins.rows(); ++p) pins.row(p) = t.coarse[std::size_t(f)].row(d.pair.pinned[p]);
    fl += (whole.fine_acap().decode_anchored(exec::seq, whole.fine_acap().encode(exec::seq, t.fine[std::size_t(f)], truth_state), pins) -
           t.fine[std::size_t(f)]).squaredNorm();
    a += (d.pair.subdivision * t.coarse[std::size_t(f)] - t.fine[std::size_t(f)]).squaredNorm();
    b += (raw[std::size_t(f)] - t.fine[std::size_t(f)]).squaredNorm();
    c += (refined[std::size_t(f)] - t.fine[std::size_t(f)]).squaredNorm();
    // the pinned corners are where the coarse frame has them
    for (Index p = 0; p < d.pair.pinned.size(); ++p)
      CHECK((raw[std::size_t(f)].row(d.pair.pinned[p]) - t.coarse[std::size_t(f)].row(d.pair.pinned[p])).norm() < 1e-12);
    // refinement left nothing inside the obstacle
    d.with_obstacle(t.index, f, [&](const auto& o) {
      for (Index i = 0; i < d.num_fine(); ++i) CHECK(o.distance(Vec3<>(refined[std::size_t(f)].row(i).transpose())) > -1e-9);
    });
  }
  const double n = double(t.num_frames() * d.num_fine());
  CHECK(ev.subdivided_rmse == doctest::Approx(std::sqrt(a / n)).epsilon(1e-9));
  CHECK(ev.synthesized_rmse == doctest::Approx(std::sqrt(b / n)).epsilon(1e-6));
  CHECK(ev.refined_rmse == doctest::Approx(std::sqrt(c / n)).epsilon(1e-6));
  CHECK(ev.decoded_truth_rmse == doctest::Approx(std::sqrt(fl / n)).epsilon(1e-9));
  CHECK(ev.decoded_truth_rmse < ev.subdivided_rmse);  // the features carry more than subdivision
  CHECK(ev.decoded_subdivided_rmse == doctest::Approx(decoded_subdivided_rmse(whole, d, t)).epsilon(1e-9));
  CHECK(ev.sequences[0].inside_before == e.inside_before);
  // every training frame's features were counted (fine: training sequences only)
  Index train_frames = 0, all_frames = 0;
  for (const auto& q : d.sequences) all_frames += q.num_frames(), train_frames += q.test ? 0 : q.num_frames();
  CHECK(whole.feature_jumps().coarse.vertex_frames == all_frames * 16);
  CHECK(whole.feature_jumps().fine.vertex_frames == train_frames * 49);
  CHECK(ev.timings.ts_acap > 0);
  CHECK(ev.timings.synthesis > 0);
  // the trained network saved and loaded into a fresh one synthesizes the same features; a model
  // of another mesh pair, or a file that is no model, is refused
  const auto model = state.path / "model.npz";
  whole.network().save(model);
  const Adjacency Ac = vertex_adjacency(d.pair.coarse.F, 16), Af = vertex_adjacency(d.pair.fine.F, 49);
  DetailSynthesisNet<float> loaded(Ac, Af, DetailSynthesisNet<float>::saved_options(model), 99);
  loaded.load(model);
  CHECK(loaded.store().values() == whole.network().store().values());
  CHECK(loaded.fine_scaling().scale == whole.network().fine_scaling().scale);
  const nn::Matrix<float> coarse_in = whole.network().normalize(std::vector<TsAcapFeatures<double>>(3, rest_features(16)), {}).coarse;
  CHECK(loaded.synthesize(exec::seq, coarse_in) == whole.network().synthesize(exec::seq, coarse_in));
  const TriMesh<> sheet4 = square_sheet(1.0, 4);
  DetailSynthesisNet<float> wrong(vertex_adjacency(sheet4.F, 25), Af, net, 1);
  CHECK(test::typed_error_of<ArgumentError>([&] { wrong.load(model); }).find("16 / 49") != std::string::npos);
  CHECK(!test::typed_error_of<ParseError>([&] { loaded.load(ckpt); }).empty());

  MESSAGE("held out (12 epochs): subdivided ", ev.subdivided_rmse, " m, synthesized ", ev.synthesized_rmse, " m, refined ", ev.refined_rmse,
          " m, true features decoded ", ev.decoded_truth_rmse, " m");
}

TEST_CASE("evaluate_upsampling: the core paper's methods on a cloth pair, whose LR mesh is a surface") {
  const ClothData d = read_cloth_data(dataset());
  auto problem = cloth_upsampling_problem(exec::seq, d, 12, 5);
  CHECK(problem.lr.T.rows() == 0);
  // the LR graph runs along the coarse triangles' edges: self first, then a mesh neighbour
  REQUIRE(problem.lr_graph);
  const Adjacency A = vertex_adjacency(d.pair.coarse.F, 16);
  for (Index i = 0; i < 16; ++i) {
    CHECK((*problem.lr_graph)(i, 0) == i);
    const auto nb = A[i];
    CHECK(std::find(nb.begin(), nb.end(), VIndex((*problem.lr_graph)(i, 1))) != nb.end());
  }
  const data::PairedFrames<> train = cloth_paired_frames(d, false), test = cloth_paired_frames(d, true);
  CHECK(train.sequence_names.size() == 4);
  CHECK(test.num_frames() == d.sequences[4].num_frames());
  CHECK(test.hr(3) == d.sequences[4].fine[3]);

  // A fine cloth that IS the subdivided coarse one is a linear map of each vertex's few nearest
  // coarse vertices (Loop's stencil: at most 7, within the 12 geodesically nearest on this grid,
  // whose diagonal ties would cut 8): the local-linear map learns it exactly from the training
  // sequences and reproduces the held-out ones
  ClothData loop = d;
  for (auto& s : loop.sequences)
    for (std::size_t f = 0; f < s.coarse.size(); ++f) s.fine[f] = d.pair.subdivision * s.coarse[f];
  interp::LocalLinear<> exact({.k = 12});
  const auto e0 = evaluate_upsampling(exec::seq, loop, problem, cloth_paired_frames(loop, false), exact, "local_linear", interp::LocalLinearTrainOptions{.lambda = 1e-12});
  CHECK(e0.rmse < 1e-6);

  // on the simulated fine cloth: the figures are the per-frame distances of the method's output
  interp::LocalLinear<> local({.k = 8});
  const auto e1 = evaluate_upsampling(exec::omp, d, problem, train, local, "local_linear");
  REQUIRE(e1.sequences.size() == 1);
  CHECK(e1.sequences[0].name == d.sequences[4].name);
  CHECK(e1.frames == d.sequences[4].num_frames());
  double sum = 0;
  Points<> hr(49, 3);
  REQUIRE(e1.sequences[0].frame_rmse.size() == std::size_t(test.num_frames()));
  for (Index f = 0; f < test.num_frames(); ++f) {
    local.apply(exec::seq, Points<>(test.lr(f) - problem.lr.V), hr);
    const double frame = (problem.hr.V + hr - test.hr(f)).squaredNorm();
    CHECK(e1.sequences[0].frame_rmse[std::size_t(f)] == doctest::Approx(std::sqrt(frame / 49)).epsilon(1e-9));
    sum += frame;
  }
  CHECK(e1.rmse == doctest::Approx(std::sqrt(sum / double(test.num_frames() * 49))).epsilon(1e-9));
  CHECK(e1.rmse > e0.rmse);

  // the super-resolution network itself: its first EdgeConv reads the graph from the triangles
  interp::NetworkRecipe recipe;
  recipe.epochs = 1;
  recipe.up_k = 8;
  recipe.residual_base = "local_linear";
  recipe.displacement_scale = 0;
  auto cfg = recipe.config(data::displacements(train, problem.lr.V, problem.hr.V));
  cfg.residual_base_k = 8;
  interp::Learned<> net(cfg, 1);
  const auto e2 = evaluate_upsampling(exec::omp, d, problem, train, net, "network");
  CHECK(std::isfinite(e2.rmse));
  CHECK(e2.rmse > 0);
  CHECK(e2.seconds_per_frame > 0);
  MESSAGE("held out: local-linear ", e1.rmse, " m, network (1 epoch) ", e2.rmse, " m");

  problem.hr.V.conservativeResize(48, 3);
  CHECK(test::typed_error_of<ShapeError>([&] { evaluate_upsampling(exec::seq, d, problem, train, local, "x"); }).find("evaluate_upsampling") !=
        std::string::npos);
}

TEST_CASE("FeatureJumps: counts rotation-vector jumps beyond pi in time and across edges, nothing below") {
  Edges E(3, 2);
  E << 0, 1, 1, 2, 0, 2;
  std::vector<TsAcapFeatures<double>> seq(3, rest_features(3));
  seq[1](0, 0) = 3.0;  // vertex 0 turns 3 rad about x: below pi from frame 0, and from its neighbours
  seq[2](0, 0) = 3.0 - 2 * std::numbers::pi;  // the same rotation one cycle down: a 2π jump in time and across both its edges
  seq[2](1, 1) = 0.5;
  FeatureJumps::Counts j;
  j.add(seq, E);
  CHECK(j.temporal == 1);
  CHECK(j.spatial == 2);
  CHECK(j.vertex_frames == 9);
  CHECK(j.edge_frames == 9);
  CHECK(j.largest_angle == doctest::Approx(2 * std::numbers::pi - 3.0));
}

}  // namespace shell_test_cloth_synthesis
