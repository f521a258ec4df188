// interp::Learned: the super-resolution network as a TrainableInterpolator (normalization,
// geometry, training, inference and model files owned by the library, not the tool).
#include <simsr/interp/embedded.hpp>
#include <simsr/interp/learned.hpp>
#include <simsr/interp/learned_inference.hpp>
#include <simsr/interp/network_recipe.hpp>
#include <simsr/mesh/generators.hpp>

#include <doctest/doctest.h>

#include "../support/allocation_check.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <random>

using namespace simsr;

namespace {

struct NetScene {
  interp::UpsamplingProblem<> problem;
  data::PairedFrames<> frames;  // displacements
};

/// An LR box, an HR sphere inside it, F frames of smooth random motion (displacements).
NetScene net_scene(Index f, unsigned seed) {
  NetScene s;
  s.problem.lr = box_tet_mesh<double>(3, 3, 3, Vec3<>(-0.1, -0.1, -0.1), Vec3<>(0.1, 0.1, 0.1));
  s.problem.hr = icosphere<double>(2, 0.08);
  s.problem.ensure_neighborhoods(exec::seq, 10);
  const Index n = s.problem.num_lr(), m = s.problem.num_hr();
  std::mt19937 rng(seed);
  std::normal_distribution<double> g(0.0, 0.01);
  s.frames.lowres.resize(f, 3 * n);
  s.frames.highres.resize(f, 3 * m);
  s.frames.controls.resize(f, 0);
  for (Index i = 0; i < f; ++i) {
    const Eigen::RowVector3d a(g(rng), g(rng), g(rng)), b(g(rng), g(rng), g(rng));
    for (Index v = 0; v < n; ++v) s.frames.lr(i).row(v) = a + b * (s.problem.lr.V(v, 0) * 10) * (s.problem.lr.V(v, 1) * 10);
    for (Index v = 0; v < m; ++v) s.frames.hr(i).row(v) = a + b * (s.problem.hr.V(v, 0) * 10) * (s.problem.hr.V(v, 1) * 10);
    s.frames.ids.push_back(i);
  }
  return s;
}

nn::NetworkConfig residual_config() {
  nn::NetworkConfig c = nn::NetworkConfig::official();
  c.residual = true;
  return c;
}

interp::NetworkTrainOptions quick(Index epochs) {
  interp::NetworkTrainOptions o;
  o.trainer.epochs = epochs;
  o.trainer.batch_size = 4;
  o.trainer.lr = 1e-3;
  o.trainer.progress = false;
  o.trainer.seed = 3;
  return o;
}

std::filesystem::path tmp(const std::string& name) {
  const auto dir = std::filesystem::path(SIMSR_TEST_TMP_DIR) / "learned";
  std::filesystem::create_directories(dir);
  return dir / name;
}

}  // namespace

TEST_CASE("Learned: the untrained residual network is exactly the Embedded interpolation") {
  auto s = net_scene(3, 1);
  interp::Learned<> net(residual_config());
  net.fit(exec::omp, s.problem);
  interp::Embedded<> e;
  e.fit(exec::omp, s.problem);
  Points<> a(s.problem.num_hr(), 3), b(s.problem.num_hr(), 3);
  for (Index f = 0; f < 3; ++f) {
    const Points<> in = s.frames.lr(f);
    net.apply(exec::omp, in, a);
    e.apply(exec::omp, in, b);
    // the output layer starts at zero; what differs is float32 normalization of the input
    CHECK((a - b).cwiseAbs().maxCoeff() <= 1e-6 * (1.0 + b.cwiseAbs().maxCoeff()));
  }
}

TEST_CASE("Learned: train, held-out error, seq == omp, save and load give the same predictions") {
  auto s = net_scene(10, 2);
  const auto train = s.frames.select(std::vector<Index>{0, 1, 2, 3, 4, 5, 6, 7});
  const auto held = s.frames.select(std::vector<Index>{8, 9});
  interp::Learned<> a(residual_config(), 5), b(residual_config(), 5);
  a.fit(exec::seq, s.problem);
  b.fit(exec::omp, s.problem);
  auto o = quick(2);
  o.holdout = &held;
  a.train(exec::seq, train, o);
  b.train(exec::omp, train, o);
  REQUIRE(a.history().size() == 2);
  CHECK(a.history().back().holdout_mean_error >= 0);
  CHECK(a.steps() == 4);
  Points<> pa(s.problem.num_hr(), 3), pb(s.problem.num_hr(), 3), pc(s.problem.num_hr(), 3);
  const Points<> in = held.lr(0);
  a.apply(exec::seq, in, pa);
  b.apply(exec::omp, in, pb);
  CHECK(pa == pb);
  const auto file = tmp("model.npz");
  a.save(file);
  auto c = interp::Learned<>::from_model_file(file);
  c.fit(exec::omp, s.problem);  // checks the rest shapes only
  c.apply(exec::omp, in, pc);
  CHECK(pa == pc);
  auto other = net_scene(1, 9);
  other.problem.hr.V *= 1.01;
  auto d = interp::Learned<>::from_model_file(file);
  CHECK_THROWS_WITH_AS(d.fit(exec::seq, other.problem), doctest::Contains("trained on other rest shapes"), ArgumentError);
}

TEST_CASE("Learned: the displacement scale is undone exactly: Embedded at start, the trainer's held-out error is apply's" * doctest::test_suite("single-threaded")) {
  auto s = net_scene(10, 6);
  for (double k : {0.5, 7.0, 40.0}) {
    CAPTURE(k);
    nn::NetworkConfig cfg = residual_config();
    cfg.displacement_scale = k;
    CHECK(cfg.displacement_unit() == doctest::Approx(cfg.norm_std / k));
    interp::Learned<> net(cfg, 2);
    net.fit(exec::seq, s.problem);
    interp::Embedded<> e;
    e.fit(exec::seq, s.problem);
    Points<> a(s.problem.num_hr(), 3), b(s.problem.num_hr(), 3);
    const Points<> in = s.frames.lr(0);
    net.apply(exec::seq, in, a);
    e.apply(exec::seq, in, b);
    CHECK((a - b).cwiseAbs().maxCoeff() <= 1e-6 * (1.0 + b.cwiseAbs().maxCoeff()));
    // After training, the trainer's held-out error (network units × σ / k) is apply's, measured here.
    const auto train = s.frames.select(std::vector<Index>{0, 1, 2, 3, 4, 5, 6, 7});
    const auto held = s.frames.select(std::vector<Index>{8, 9});
    auto o = quick(1);
    o.holdout = &held;
    net.train(exec::seq, train, o);
    double sum = 0;
    for (Index f = 0; f < 2; ++f) {
      const Points<> x = held.lr(f);
      net.apply(exec::seq, x, a);
      sum += (a - held.hr(f)).rowwise().norm().sum();
    }
    CHECK(net.history().back().holdout_mean_error == doctest::Approx(sum / double(2 * s.problem.num_hr())).epsilon(1e-4));
  }
  nn::NetworkConfig bad = residual_config();
  bad.displacement_scale = 0;
  CHECK_THROWS_WITH_AS(bad.validate(), doctest::Contains("displacement_scale"), ArgumentError);
  bad.displacement_scale = 3;
  CHECK(nn::NetworkConfig::from_json(bad.to_json()).displacement_scale == 3);
}

TEST_CASE("NetworkRecipe: the automatic displacement scale makes the training frames' normalized HR RMS 1") {
  auto s = net_scene(6, 7);
  interp::NetworkRecipe r;
  r.displacement_scale = 0;
  const auto cfg = r.config(s.frames);
  double sq = 0;
  for (Index i = 0; i < s.frames.highres.size(); ++i) sq += std::pow(s.frames.highres.data()[i] / cfg.norm_std * cfg.displacement_scale, 2);
  CHECK(std::sqrt(sq / double(s.frames.highres.size())) == doctest::Approx(1.0));
  CHECK(r.config().displacement_scale == 1.0);  // without frames: nothing to measure, the official 1
  r.displacement_scale = 4;
  CHECK(r.config(s.frames).displacement_scale == 4);
  r.displacement_scale = -1;
  CHECK_THROWS_AS(r.config(), ArgumentError);
  r.displacement_scale = 0;
  auto still = s.frames;
  still.highres.setZero();
  CHECK_THROWS_WITH_AS(r.config(still), doctest::Contains("all zero"), ArgumentError);
}

TEST_CASE("Learned: a run resumed from its checkpoint ends where the uninterrupted run ends" * doctest::test_suite("single-threaded")) {
  auto s = net_scene(8, 3);
  const auto ckpt = tmp("checkpoint.npz");
  interp::Learned<> full(residual_config(), 1), first(residual_config(), 1), rest(residual_config(), 1);
  full.fit(exec::seq, s.problem);
  full.train(exec::seq, s.frames, quick(2));
  first.fit(exec::seq, s.problem);
  auto o1 = quick(1);
  o1.checkpoint = ckpt;
  first.train(exec::seq, s.frames, o1);
  rest.fit(exec::seq, s.problem);
  auto o2 = quick(2);
  o2.resume = ckpt;
  rest.train(exec::seq, s.frames, o2);
  Points<> a(s.problem.num_hr(), 3), b(s.problem.num_hr(), 3);
  const Points<> in = s.frames.lr(3);
  full.apply(exec::seq, in, a);
  rest.apply(exec::seq, in, b);
  CHECK(a == b);
}

TEST_CASE("Learned: bad inputs are errors naming the vertex; the w/o CU ablation fits") {
  auto s = net_scene(2, 4);
  interp::Learned<> net(residual_config());
  Points<> in(s.problem.num_lr(), 3), out(s.problem.num_hr(), 3);
  in.setZero();
  CHECK_THROWS_WITH_AS(net.apply(exec::seq, in, out), doctest::Contains("before fit"), ArgumentError);
  net.fit(exec::seq, s.problem);
  in(7, 1) = std::nan("");
  CHECK_THROWS_WITH_AS(net.apply(exec::seq, in, out), doctest::Contains("vertex 7"), ArgumentError);
  in(7, 1) = 1e300;
  CHECK_THROWS_WITH_AS(net.apply(exec::seq, in, out), doctest::Contains("float range"), ArgumentError);
  Points<> wrong(s.problem.num_hr() + 1, 3);
  in.setZero();
  CHECK_THROWS_AS(net.apply(exec::seq, in, wrong), ShapeError);
  nn::NetworkConfig wocu = residual_config();
  wocu.upsampling = nn::UpsamplingKind::table;
  interp::Learned<> table(wocu);
  table.fit(exec::omp, s.problem);
  table.apply(exec::omp, in, out);
  CHECK(out.allFinite());
}

TEST_CASE("Learned over the local-linear base: untrained it is interp::LocalLinear; trained, saved and loaded it predicts the same") {
  auto s = net_scene(12, 4);
  const auto train = s.frames.select(std::vector<Index>{0, 1, 2, 3, 4, 5, 6, 7, 8, 9});
  nn::NetworkConfig cfg = residual_config();
  cfg.residual_base = nn::ResidualBase::local_linear;
  cfg.residual_base_k = 6;
  interp::Learned<> untrained(cfg, 1);
  untrained.fit(exec::omp, s.problem);
  Points<> a(s.problem.num_hr(), 3), b(s.problem.num_hr(), 3), c(s.problem.num_hr(), 3);
  const Points<> in = s.frames.lr(11);
  CHECK_THROWS_WITH_AS(untrained.apply(exec::omp, in, a), doctest::Contains("not fitted yet"), ArgumentError);
  CHECK_THROWS_AS(untrained.network().set_residual_map(Eigen::SparseMatrix<double, Eigen::RowMajor>(3, 3)), ShapeError);
  interp::Learned<> over_embedded(residual_config(), 1);
  over_embedded.fit(exec::omp, s.problem);
  CHECK_THROWS_WITH_AS(over_embedded.network().set_residual_map(Eigen::SparseMatrix<double, Eigen::RowMajor>(3 * s.problem.num_hr(), 3 * s.problem.num_lr())),
                       doctest::Contains("local_linear only"), ArgumentError);
  untrained.train(exec::omp, train, quick(0));  // fits the base, no step
  interp::LocalLinear<> ll(interp::LocalLinearOptions{.k = 6});
  ll.fit(exec::omp, s.problem);
  ll.train(exec::omp, train, {});
  REQUIRE(untrained.base_info() != nullptr);
  CHECK(untrained.base_info()->lambda_relative == ll.info().lambda_relative);
  untrained.apply(exec::omp, in, a);
  ll.apply(exec::omp, in, b);
  CHECK((a - b).cwiseAbs().maxCoeff() <= 1e-5 * (1.0 + b.cwiseAbs().maxCoeff()));  // float32 network units

  interp::Learned<> net(cfg, 1);
  net.fit(exec::omp, s.problem);
  net.train(exec::omp, train, quick(2));
  net.apply(exec::omp, in, a);
  CHECK((a - b).cwiseAbs().maxCoeff() > 0);  // it trained
  const auto file = tmp("model_local_linear.npz");
  net.save(file);
  auto loaded = interp::Learned<>::from_model_file(file);
  CHECK(loaded.base_info() == nullptr);
  loaded.fit(exec::omp, s.problem);
  loaded.apply(exec::omp, in, c);
  CHECK(a == c);
  // the map travels in the model file; without it the file is refused, naming the arrays
  const auto arrays = nn::read_model_arrays(file);
  auto without = [&](const std::vector<std::string>& names) {
    io::NpzArrays out;
    for (const auto& [k, v] : arrays)
      if (std::find(names.begin(), names.end(), k) == names.end()) out.insert_or_assign(k, v);
    return out;
  };
  CHECK_THROWS_WITH_AS(nn::model_data(without({"residual_map_data"}), "m.npz"), doctest::Contains("residual_map_data"), ArgumentError);
  CHECK_THROWS_WITH_AS(nn::model_data(without({"residual_map_indptr", "residual_map_indices", "residual_map_data"}), "m.npz"),
                       doctest::Contains("local-linear base"), ArgumentError);
  auto bad = without({});
  auto values = arrays.at("residual_map_data").to_vector<double>();
  values[7] = std::nan("");
  bad.insert_or_assign("residual_map_data", io::make_npy<double>({std::int64_t(values.size())}, values.data()));
  CHECK_THROWS_WITH_AS(nn::model_data(bad, "m.npz"), doctest::Contains("not finite"), ArgumentError);
}

TEST_CASE("NetworkRecipe: the residual base by name; only a non-Embedded base enters the fingerprint JSON") {
  interp::NetworkRecipe r;
  CHECK(r.config().residual_base == nn::ResidualBase::embedded);
  CHECK_FALSE(r.to_json().contains("residual_base"));
  r.residual_base = "local_linear";
  CHECK(r.config().residual_base == nn::ResidualBase::local_linear);
  CHECK(r.to_json().at("residual_base") == "local_linear");
  CHECK(nn::NetworkConfig::from_json(r.config().to_json()).residual_base == nn::ResidualBase::local_linear);
  CHECK(interp::Learned<>::neighborhoods_needed(r.config()) == 20);  // the base's k beyond upK 10
  r.residual_base = "ridge";
  CHECK_THROWS_AS(r.config(), ArgumentError);
  r.residual_base = "embedded";
  CHECK(interp::Learned<>::neighborhoods_needed(r.config()) == 10);
}

TEST_CASE("LearnedInference (host memory): the device path's launches give Learned::apply's prediction; its checks name the vertex") {
  auto s = net_scene(8, 6);
  interp::Learned<> net(residual_config(), 7);
  net.fit(exec::omp, s.problem);
  net.train(exec::omp, s.frames, quick(1));
  interp::HostLearned<> plan(exec::omp, net);
  CHECK(plan.num_lr() == s.problem.num_lr());
  CHECK(plan.num_hr() == s.problem.num_hr());
  Points<> expected(s.problem.num_hr(), 3), got_seq(s.problem.num_hr(), 3), got_omp(s.problem.num_hr(), 3);
  for (Index f = 0; f < 3; ++f) {
    const Points<> in = s.frames.lr(f);
    net.apply(exec::seq, in, expected);
    plan.apply(exec::seq, in, got_seq);
    plan.apply(exec::omp, in, got_omp);
    CHECK(got_seq == got_omp);
    // the network's float rounding (InferenceNet sums in another order), scaled to mesh units
    CHECK((got_seq - expected).cwiseAbs().maxCoeff() <= 1e-5 * (1e-3 + expected.cwiseAbs().maxCoeff()));
  }
  // the host-array call warm allocates nothing; a column block (row stride 5) reaches it through
  // ConstPointsRef's temporary, the same frame
  const Points<> frame = s.frames.lr(0);
  net.apply(exec::seq, frame, expected);
  plan.apply(exec::seq, frame, got_seq);
  const long before = simsr_test_malloc_count();
  plan.apply(exec::seq, frame, got_seq);
  SIMSR_CHECK_NO_ALLOCATION(exec::seq, simsr_test_malloc_count() - before);
  Eigen::Matrix<double, Eigen::Dynamic, 5, Eigen::RowMajor> wide = Eigen::Matrix<double, Eigen::Dynamic, 5, Eigen::RowMajor>::Zero(frame.rows(), 5);
  wide.leftCols(3) = frame;
  plan.apply(exec::seq, wide.leftCols(3), got_omp);
  CHECK(got_omp == got_seq);
  // Learned::apply's input checks, the same vertex named
  Points<> in(s.problem.num_lr(), 3), out(s.problem.num_hr(), 3);
  in.setZero();
  in(7, 1) = std::nan("");
  CHECK_THROWS_WITH_AS(plan.apply(exec::seq, in, out), doctest::Contains("vertex 7 is nan: not finite"), ArgumentError);
  in(7, 1) = 1e300;
  CHECK_THROWS_WITH_AS(plan.apply(exec::omp, in, out), doctest::Contains("float range"), ArgumentError);
  in.setZero();
  Points<> wrong(s.problem.num_hr() + 1, 3);
  CHECK_THROWS_AS(plan.apply(exec::seq, in, wrong), ShapeError);
  // a non-finite prediction is a NumericalError, as Learned::apply's
  auto& store = net.network().store();
  store.values(store.at("net_decoder.decoder.last_layer.fc.bias"))[1] = std::numeric_limits<float>::infinity();
  net.network().parameters_changed();
  CHECK_THROWS_AS(net.apply(exec::seq, in, out), NumericalError);
  interp::HostLearned<> broken(exec::seq, net);
  CHECK_THROWS_WITH_AS(broken.apply(exec::seq, in, out), doctest::Contains("HR vertex 0"), NumericalError);
  interp::Learned<> unfitted;
  CHECK_THROWS_AS(interp::HostLearned<>(exec::seq, unfitted), ArgumentError);
}
