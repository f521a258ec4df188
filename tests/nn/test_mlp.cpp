#include <simsr/nn/mlp.hpp>

#include <array>
#include <span>
#include <utility>
#include <vector>

#include "gradient_check.hpp"

using namespace simsr;
using nn::Matrix;
using test::random_matrix;

namespace {
/// A random stack of 1–3 stages: widths, bias, BatchNorm (running statistics away from 0 and 1),
/// LeakyReLU, sine or no activation.
std::vector<nn::MlpStage> random_stages(std::mt19937_64& rng, Index in) {
  std::uniform_int_distribution<int> count(1, 3), width(1, 12), act(0, 2), coin(0, 1);
  std::vector<nn::MlpStage> st;
  const int n = count(rng);
  for (int i = 0; i < n; ++i) {
    nn::MlpStage s = nn::MlpStage::linear(i == 0 ? in : st.back().out, width(rng), "lin" + std::to_string(i));
    if (coin(rng)) s.no_bias();
    if (coin(rng)) s.norm("bn" + std::to_string(i));
    if (const int a = act(rng); a == 1)
      s.then(nn::Act::leaky_relu, 0.2);
    else if (a == 2)
      s.then(nn::Act::sine, 1.3);
    st.push_back(s);
  }
  return st;
}

template <class S>
void randomize_buffers(nn::ParameterStore<S>& store, std::mt19937_64& rng) {
  for (const auto& e : store.entries()) {
    if (e.kind != nn::TensorEntry::Kind::buffer || e.size == 0 || e.name.ends_with("num_batches_tracked")) continue;
    const bool var = e.name.ends_with("running_var");
    store.buffers().segment(e.offset, e.size) = random_matrix(rng, e.size, 1, var ? 0.3 : -1.0, var ? 2.0 : 1.0).template cast<S>();
  }
}
/// One random stack twice: in double with random BatchNorm statistics, and its float copy.
struct TwinMlps {
  nn::ParameterStore<double> sd;
  nn::ParameterStore<float> sf;
  nn::Rng init_d, init_f;
  nn::Mlp<double> d;
  nn::Mlp<float> f;
  TwinMlps(const std::vector<nn::MlpStage>& stages, int seed, std::mt19937_64& rng)
      : init_d(std::uint64_t(seed)), init_f(std::uint64_t(seed)), d(sd, "m", stages, init_d), f(sf, "m", stages, init_f) {
    randomize_buffers(sd, rng);
    sf.values() = sd.values().cast<float>();
    sf.buffers() = sd.buffers().cast<float>();
  }
};
}  // namespace

TEST_CASE("nn::Mlp::forward_eval_parts: the concatenation's eval forward, per-item parts once per item (random stacks and splits)") {
  std::mt19937_64 rng(90);
  std::uniform_int_distribution<int> parts_n(1, 4), width(1, 7), items(1, 4), rows(1, 9), coin(0, 1);
  for (int trial = 0; trial < 60; ++trial) {
    const Index B = items(rng), n = rows(rng), R = B * n, P = parts_n(rng);
    std::vector<Index> widths;
    std::vector<bool> per_item;
    Index in = 0;
    for (Index p = 0; p < P; ++p) {
      widths.push_back(width(rng));
      per_item.push_back(p > 0 && coin(rng));  // part 0 always has a row per output row
      in += widths.back();
    }
    const auto stages = random_stages(rng, in);
    TwinMlps twins(stages, trial, rng);
    auto& sd = twins.sd;
    auto& mlp = twins.d;
    auto& mlpf = twins.f;
    INFO("trial " << trial << ": B " << B << " rows per item " << n << " parts " << P << " in " << in << " stages " << stages.size());

    // the parts, and their concatenation with each per-item row repeated over its item's rows
    std::vector<Matrix<double>> values;
    Matrix<double> cat(R, in);
    Index off = 0;
    for (Index p = 0; p < P; ++p) {
      values.push_back(random_matrix(rng, per_item[std::size_t(p)] ? B : R, widths[std::size_t(p)], -2.0, 2.0));
      for (Index r = 0; r < R; ++r) cat.block(r, off, 1, widths[std::size_t(p)]) = values.back().row(per_item[std::size_t(p)] ? r / n : r);
      off += widths[std::size_t(p)];
    }
    auto run = [&](auto& m, auto policy, const auto& v, auto& out) {  // the span overload: the trial's number of parts
      std::vector<typename std::decay_t<decltype(m)>::InputPart> ps;
      for (Index p = 0; p < P; ++p) ps.push_back({v[std::size_t(p)], per_item[std::size_t(p)]});
      m.forward_eval_parts(policy, std::span<const typename std::decay_t<decltype(m)>::InputPart>(ps), n, out);
    };
    Matrix<double> yd, refd;
    run(mlp, exec::seq, values, yd);
    mlp.forward(exec::seq, nn::Mode::eval, cat, refd);
    const double scale = 1.0 + refd.cwiseAbs().maxCoeff();
    CHECK((yd - refd).cwiseAbs().maxCoeff() <= 1e-13 * scale * double(in));

    std::vector<Matrix<float>> vf;
    for (const auto& v : values) vf.push_back(v.cast<float>());
    const Matrix<float> catf = cat.cast<float>();
    Matrix<float> yf, yf_omp, reff;
    run(mlpf, exec::seq, vf, yf);
    run(mlpf, exec::omp, vf, yf_omp);
    CHECK(test::bitwise_equal(yf, yf_omp));
    mlpf.forward(exec::seq, nn::Mode::eval, catf, reff);
    CHECK((yf - reff).cwiseAbs().maxCoeff() <= 1e-6f * float(scale) * float(in));

    // a backward after it: the gradients of a backward after forward(eval) on the concatenation
    const Matrix<double> g = random_matrix(rng, R, mlp.out_features());
    Matrix<double> dx1, dx2;
    sd.zero_grad();
    mlp.forward(exec::seq, nn::Mode::eval, cat, refd);
    mlp.backward(exec::seq, cat, refd, g, &dx1);
    const nn::Vector<double> g1 = sd.gradients();
    sd.zero_grad();
    run(mlp, exec::seq, values, yd);
    mlp.backward(exec::seq, cat, yd, g, &dx2);
    CHECK(test::bitwise_equal(dx1, dx2));
    CHECK(test::bitwise_equal(g1, nn::Vector<double>(sd.gradients())));

    // warm: nothing allocated
    std::vector<nn::Mlp<float>::InputPart> parts;
    for (Index p = 0; p < P; ++p) parts.push_back({vf[std::size_t(p)], per_item[std::size_t(p)]});
    mlpf.forward_eval_parts(exec::omp, std::span<const nn::Mlp<float>::InputPart>(parts), n, yf);
    const long before = simsr_test_malloc_count();
    mlpf.forward_eval_parts(exec::omp, std::span<const nn::Mlp<float>::InputPart>(parts), n, yf);
    SIMSR_CHECK_NO_ALLOCATION(exec::omp, simsr_test_malloc_count() - before);
  }
}

TEST_CASE("nn::Mlp: the eval forward split after stage 0's products (random stacks; a linear map of the rows in between)") {
  std::mt19937_64 rng(93);
  std::uniform_int_distribution<int> width(1, 9), rows(1, 700);
  for (int trial = 0; trial < 40; ++trial) {
    const Index in = width(rng), R = rows(rng);
    const auto stages = random_stages(rng, in);
    TwinMlps twins(stages, trial, rng);
    auto& mlp = twins.d;
    auto& mlpf = twins.f;
    INFO("trial " << trial << ": rows " << R << " in " << in << " stages " << stages.size());
    const Index H = stages[0].out;
    const Matrix<double> x = random_matrix(rng, R, in, -2.0, 2.0);
    const Matrix<float> xf = x.cast<float>();

    // products handed back unchanged: forward(eval) to rounding (there the sums start at the bias,
    // here the bias is added to them), seq == omp bitwise
    Matrix<float> pf, yf, yf_omp, reff;
    mlpf.first_linear_products(exec::omp, xf, pf);
    REQUIRE(pf.rows() == R);
    REQUIRE(pf.cols() == H);
    auto copy_rows = [](const Matrix<float>& p) {
      return [&p](Index b, Index e, float* y, Index ld) {
        for (Index r = b; r < e; ++r) std::copy_n(p.row(r).data(), p.cols(), y + (r - b) * ld);
      };
    };
    mlpf.forward_eval_from_products(exec::seq, R, copy_rows(pf), yf);
    mlpf.forward_eval_from_products(exec::omp, R, copy_rows(pf), yf_omp);
    mlpf.forward(exec::seq, nn::Mode::eval, xf, reff);
    CHECK(test::bitwise_equal(yf, yf_omp));
    CHECK((yf - reff).cwiseAbs().maxCoeff() <= 1e-5f * (1.0f + reff.cwiseAbs().maxCoeff()));
    Matrix<float> pf_seq;
    mlpf.first_linear_products(exec::seq, xf, pf_seq);
    CHECK(test::bitwise_equal(pf, pf_seq));

    // a linear map of the rows between the two halves (each output row a random combination of
    // three input rows): the eval forward of the mapped input, in double to rounding
    std::vector<std::array<std::pair<Index, double>, 3>> map(static_cast<std::size_t>(R));
    Matrix<double> mapped = Matrix<double>::Zero(R, in);
    for (Index r = 0; r < R; ++r)
      for (auto& [j, c] : map[std::size_t(r)]) {
        j = Index(rng() % std::uint64_t(R));
        c = std::uniform_real_distribution<double>(-1, 1)(rng);
        mapped.row(r) += c * x.row(j);
      }
    Matrix<double> pd, yd, refd;
    mlp.first_linear_products(exec::seq, x, pd);
    mlp.forward_eval_from_products(
        exec::omp, R,
        [&](Index b, Index e, double* y, Index ld) {
          for (Index r = b; r < e; ++r) {
            Eigen::Map<Eigen::RowVectorXd> o(y + (r - b) * ld, H);
            o.setZero();
            for (const auto& [j, c] : map[std::size_t(r)]) o += c * pd.row(j);
          }
        },
        yd);
    mlp.forward(exec::seq, nn::Mode::eval, mapped, refd);
    CHECK((yd - refd).cwiseAbs().maxCoeff() <= 1e-12 * (1.0 + refd.cwiseAbs().maxCoeff()));

    // warm: nothing allocated
    const long before = simsr_test_malloc_count();
    mlpf.first_linear_products(exec::omp, xf, pf);
    mlpf.forward_eval_from_products(exec::omp, R, copy_rows(pf), yf);
    SIMSR_CHECK_NO_ALLOCATION(exec::omp, simsr_test_malloc_count() - before);
  }
  // refused: the wrong input width, BatchNorm on batch statistics
  nn::ParameterStore<double> store;
  nn::Rng init(1);
  nn::Mlp<double> mlp(store, "m", {nn::MlpStage::linear(5, 3, "lin").then(nn::Act::sine, 1.0)}, init);
  Matrix<double> p, y;
  CHECK_THROWS_AS(mlp.first_linear_products(exec::seq, Matrix<double>(4, 6), p), ShapeError);
  CHECK_THROWS_AS(mlp.forward_eval_from_products(exec::seq, -1, [](Index, Index, double*, Index) {}, y), ArgumentError);
  nn::ParameterStore<double> s2;
  nn::Mlp<double> batch_stats(s2, "m", {nn::MlpStage::linear(5, 3, "lin").norm("bn", {.track_running_stats = false})}, init);
  CHECK_THROWS_AS(batch_stats.forward_eval_from_products(exec::seq, 4, [](Index, Index, double*, Index) {}, y), ArgumentError);
}

TEST_CASE("nn::Mlp::forward_eval_parts: bad parts are refused by name") {
  std::mt19937_64 rng(91);
  nn::ParameterStore<double> store;
  nn::Rng init(1);
  nn::Mlp<double> mlp(store, "m", {nn::MlpStage::linear(5, 3, "lin").norm("bn").then(nn::Act::leaky_relu, 0.2)}, init);
  const Matrix<double> a = random_matrix(rng, 6, 3), b = random_matrix(rng, 2, 2), b6 = random_matrix(rng, 6, 2);
  Matrix<double> y;
  mlp.forward_eval_parts(exec::seq, {{a, false}, {b, true}}, 3, y);
  CHECK(y.rows() == 6);
  CHECK_THROWS_AS(mlp.forward_eval_parts(exec::seq, {{a, false}, {a, true}}, 3, y), ShapeError);  // widths add up to 6, not 5
  CHECK_THROWS_AS(mlp.forward_eval_parts(exec::seq, {{a, false}, {b6, true}}, 3, y), ShapeError);  // a per-item part with a row per row
  CHECK_THROWS_AS(mlp.forward_eval_parts(exec::seq, {{a, false}, {b, true}}, 4, y), ShapeError);   // 6 rows are not items of 4
  CHECK_THROWS_AS(mlp.forward_eval_parts(exec::seq, {{a, true}, {b, true}}, 3, y), ArgumentError);  // nothing per row
  CHECK_THROWS_AS(mlp.forward_eval_parts(exec::seq, {{a, false}, {b, true}}, 0, y), ArgumentError);
  nn::ParameterStore<double> s2;
  nn::Mlp<double> batch_stats(s2, "m", {nn::MlpStage::linear(5, 3, "lin").norm("bn", {.track_running_stats = false})}, init);
  CHECK_THROWS_AS(batch_stats.forward_eval_parts(exec::seq, {{a, false}, {b, true}}, 3, y), ArgumentError);  // BatchNorm on batch statistics
}
