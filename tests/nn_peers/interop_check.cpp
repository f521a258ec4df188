/// The C++ half of the PyTorch interop test (driven by test_torch_interop.py, which makes the
/// fixtures with scripts/peers/official_model.py and converts the checkpoint with
/// scripts/torch_to_simsr.py):
///
///     interop_check --model MODEL.npz --state DIR/state_dict.npz --io DIR/io.npz --data-dir BUNNY
///
/// loads the converted model, rebuilds the official network, and compares with PyTorch's
/// recorded tensors: the inputs (normalization of the bunny frames), the eval forward (code z,
/// the dynamic feature graph, every max pooling's choices, upsampling weights, z^H, the
/// prediction) both through forward() and through the precomputed-weights inference path, then
/// one training step (loss terms, every parameter gradient, the parameters after one Adam step). Prints one JSON object: per tensor
/// the max |ours − torch| and that divided by max |torch|; exit 0 when every relative error is
/// at most --tol (default 1e-5), 1 otherwise, 2 on bad usage.

#include <simsr/io/npz.hpp>
#include <simsr/nn/adam.hpp>
#include <simsr/nn/model_file.hpp>
#include <simsr/nn/super_resolution_loss.hpp>

#include <nlohmann/json.hpp>

#include <cstdio>
#include <iostream>
#include <optional>
#include <set>
#include <string>
#include <vector>
#include <span>
#include <utility>

using namespace simsr;
using nn::Matrix;

namespace {

struct Report {
  nlohmann::json j = nlohmann::json::object();
  double tol = 1e-5;
  /// Denominator floor: a tensor whose exact value is 0 (the softmax-invariant last bias of f_θ)
  /// is compared by its absolute error, at the precision's rounding level.
  double floor = 1e-12;
  bool ok = true;
  /// Names of the comparisons that failed, so the driver can print them in one line.
  std::vector<std::string> failed;

  void fail(const std::string& what) {
    ok = false;
    failed.push_back(what);
  }

  template <class A, class B>
  void compare(const std::string& what, const A& ours, const B& ref) {
    if (ours.size() != ref.size()) {
      j[what] = {{"error", "size " + std::to_string(ours.size()) + " vs " + std::to_string(ref.size())}};
      fail(what);
      return;
    }
    double diff = 0, scale = 0;
    for (Index i = 0; i < Index(ref.size()); ++i) {
      diff = std::max(diff, std::abs(double(ours.data()[i]) - double(ref.data()[i])));
      scale = std::max(scale, std::abs(double(ref.data()[i])));
    }
    const double rel = diff / std::max(scale, floor);
    j[what] = {{"max_abs", diff}, {"rel", rel}, {"scale", scale}};
    if (!(rel <= tol)) fail(what);
  }
  void scalar(const std::string& what, double ours, double ref) {
    const double rel = std::abs(ours - ref) / std::max(std::abs(ref), 1e-30);
    j[what] = {{"ours", ours}, {"torch", ref}, {"rel", rel}};
    if (!(rel <= tol)) fail(what);
  }
};

template <class S>
Matrix<S> as_matrix(const io::NpyArray& a, Index cols) {
  const auto v = a.template to_vector<S>();
  return Eigen::Map<const Matrix<S>>(v.data(), Index(v.size()) / cols, cols);
}

/// How our dynamic feature graph (block 1) agrees with PyTorch's, row by row. A row may differ
/// only at a near-tie: every index in the symmetric difference of the two neighbour sets lies
/// within tol·H of the row's k-th distance (distances in double from our block-1 input features,
/// H = their largest magnitude in the item). Float32 rounding on another CPU swaps such pairs: on
/// the bunny the closest k-th/(k+1)-th gap is 2.8e-6·H, and features agree to ~1e-7·H per entry.
struct GraphAgreement {
  Index equal = 0, tied = 0, differ = 0;
};

template <class S>
GraphAgreement graph_agreement(const Matrix<S>& h, const nn::GraphIndices& ours, const std::vector<std::int64_t>& ref, Index n_points,
                               double tol) {
  GraphAgreement a;
  const Index k = ours.cols();
  for (Index r = 0; r < ours.rows(); ++r) {
    const std::set<std::int64_t> mine(ours.row(r).data(), ours.row(r).data() + k);
    const std::set<std::int64_t> theirs(ref.begin() + r * k, ref.begin() + (r + 1) * k);
    if (mine == theirs) {
      ++a.equal;
      continue;
    }
    const Index first = (r / n_points) * n_points;
    const auto item = h.middleRows(first, n_points).template cast<double>();
    const double H = item.cwiseAbs().maxCoeff();
    auto dist = [&](std::int64_t j) { return (item.row(r - first) - item.row(Index(j))).norm(); };
    double dk = 0;
    for (const auto j : mine) dk = std::max(dk, dist(j));
    bool tie = true;
    for (const auto& [from, other] : {std::pair{&mine, &theirs}, std::pair{&theirs, &mine}})
      for (const auto j : *from)
        if (!other->count(j) && !(j >= 0 && j < n_points && std::abs(dist(j) - dk) <= tol * H)) tie = false;
    ++(tie ? a.tied : a.differ);
  }
  return a;
}

/// How our max poolings' choices agree with PyTorch's. `ours` is a GroupPool's argmax (groups × C,
/// groups = items × n, the row within the group); `ref` PyTorch's indices of the same maxima laid
/// out (item, C, n). A choice may differ only at a near-tie: the values at the two rows within
/// tol·M (M the group's largest |value| in that channel). Float32 rounding on another CPU breaks
/// such ties the other way, and the max then routes its gradient elsewhere: a global max sends a
/// whole item's gradient (the sum over its N points) to another point, enough to move the
/// BatchNorm-projected gradients upstream by 6e-2 of their size (CI, stop 41). `theirs` receives
/// PyTorch's choices in our layout, for GroupPool::set_argmax. An EdgeConv's choices are edges
/// of a row of its graph, and the two graphs may list a row's neighbours in another order (a
/// near-tie in distance): with `graphs` (ours, N×k or (B·N)×k, and PyTorch's, (B, N, k)) PyTorch's
/// choice is read as the neighbour it names, found in our row.
struct MaxAgreement {
  Index equal = 0, tied = 0, differ = 0;
};

template <class S>
MaxAgreement max_agreement(const Matrix<S>& values, Index group_size, const typename nn::GroupPool<S>::ArgmaxIndices& ours,
                           const std::vector<std::int64_t>& ref, Index n, double tol, typename nn::GroupPool<S>::ArgmaxIndices& theirs,
                           std::optional<std::pair<const nn::GraphIndices*, const std::vector<std::int64_t>*>> graphs = std::nullopt) {
  MaxAgreement a;
  const Index groups = ours.rows(), C = ours.cols();
  theirs.resize(groups, C);
  if (Index(ref.size()) != groups * C || values.rows() != groups * group_size || values.cols() != C) {
    a.differ = groups * C;
    return a;
  }
  for (Index g = 0; g < groups; ++g)
    for (Index c = 0; c < C; ++c) {
      const Index item = g / n, m = g % n;
      std::int64_t t = ref[std::size_t((item * C + c) * n + m)];
      if (graphs && t >= 0 && t < group_size) {  // PyTorch's edge t of row g: the neighbour it names, in our row
        const auto& [mine, their_graph] = *graphs;
        const std::int64_t neighbour = (*their_graph)[std::size_t(g * group_size + t)];
        const Index row = g % mine->rows();
        t = -1;
        for (Index j = 0; j < group_size; ++j)
          if ((*mine)(row, j) == neighbour) t = j;
      }
      theirs(g, c) = Index(std::max<std::int64_t>(t, 0));
      if (t == ours(g, c)) {
        ++a.equal;
        continue;
      }
      if (t < 0 || t >= group_size) {
        ++a.differ;
        continue;
      }
      const Index r0 = g * group_size;
      double M = 0;
      for (Index j = 0; j < group_size; ++j) M = std::max(M, std::abs(double(values(r0 + j, c))));
      const double gap = std::abs(double(values(r0 + ours(g, c), c)) - double(values(r0 + Index(t), c)));
      ++(gap <= tol * M ? a.tied : a.differ);
    }
  return a;
}

nn::GraphIndices as_graph(const std::vector<std::int64_t>& v, Index k) {
  nn::GraphIndices g(Index(v.size()) / k, k);
  for (Index i = 0; i < g.size(); ++i) g.data()[i] = VIndex(v[std::size_t(i)]);
  return g;
}

/// Everything above in precision S; `grad_tol` bounds the gradients and the post-Adam weights.
/// `reference_io` (float32 runs): PyTorch's float64 fixture of the same weights and inputs. A
/// float32 gradient that misses PyTorch's float32 one by more than grad_tol is then held to the
/// float64 gradient instead, within twice PyTorch's own float32 error there (or grad_tol): a
/// BatchNorm bias's gradient is a sum over the batch that cancels to 2 % of its terms, and
/// PyTorch's float32 value itself was measured 5.9e-2 (relative) from its float64 one on one CI run.
template <class S>
int check(const std::string& model, const std::string& state, const std::string& iofile, const std::string& data_dir, double tol,
          double grad_tol, const std::string& reference_io = {}) {
  Report rep;
  rep.tol = tol;
  const io::NpzArrays marr = io::read_npz(model);
  nn::ModelData data = nn::model_data(marr, model);
  const io::NpzArrays fx = io::read_npz(iofile);
  const Index N = data.geometry.lr_rest.rows(), M = data.geometry.hr_rest.rows();

  nn::Rng rng(0);
  nn::SuperResolutionNet<S> net(data.config, data.geometry, rng);
  nn::load_state(net.store(), marr);
  rep.j["parameters"] = net.store().num_parameters();

  // inputs: the bunny frames normalized as dataset.py does (float32, then subtract)
  const auto frames = fx.at("frames").to_vector<std::int64_t>();
  const Index B = Index(frames.size());
  io::NpzReader train(std::filesystem::path(data_dir) / "train_frames.npz");
  const auto frame_ids = train.read("frame").to_vector<std::int64_t>();
  const io::NpyArray low = train.read("lowres"), high = train.read("highres");
  Matrix<S> ldx(B * N, 3), hdx(B * M, 3);
  const Matrix<S> lr0 = nn::normalize_positions<S>(data.geometry.lr_rest, data.config.norm_mean, data.config.norm_std);
  const Matrix<S> hr0 = nn::normalize_positions<S>(data.geometry.hr_rest, data.config.norm_mean, data.config.norm_std);
  for (Index b = 0; b < B; ++b) {
    const auto it = std::find(frame_ids.begin(), frame_ids.end(), frames[std::size_t(b)]);
    const Index f = Index(it - frame_ids.begin());
    nn::normalized_displacements(low.frame_points(f), lr0, data.config.norm_mean, data.config.norm_std, ldx.middleRows(b * N, N));
    nn::normalized_displacements(high.frame_points(f), hr0, data.config.norm_mean, data.config.norm_std, hdx.middleRows(b * M, M));
  }
  rep.compare("input/lr_rest_normalized", lr0, as_matrix<S>(fx.at("lr_rest_normalized"), 3));
  rep.compare("input/ldx", ldx, as_matrix<S>(fx.at("ldx"), 3));
  rep.compare("input/hdx", hdx, as_matrix<S>(fx.at("hdx"), 3));
  rep.compare("input/up_query", net.upsampling().query(), as_matrix<S>(fx.at("up_query"), 7));

  // eval forward. Where the two feature graphs differ only at near-ties, PyTorch's graph is
  // given to block 1 and the forward repeated, so what follows compares the same computation.
  Matrix<S> pred, pred_inf;
  auto& edge1 = net.feature_embedding().block(1).edge_conv();
  const Index k1 = edge1.k();
  auto check_graph = [&](const std::string& what) {
    const auto ref = fx.at(what + "/feature_graph").template to_vector<std::int64_t>();
    const GraphAgreement a = graph_agreement(net.feature_embedding().block_output(0), edge1.graph(), ref, N, tol);
    rep.j[what + "/feature_graph_rows_equal"] = a.equal;
    rep.j[what + "/feature_graph_rows_tied"] = a.tied;
    rep.j[what + "/feature_graph_rows"] = edge1.graph().rows();
    if (a.differ) rep.fail(what + "/feature_graph");
    if (a.tied) edge1.set_graph(as_graph(ref, k1), N);
    return a.tied > 0;
  };
  // Each block's edge max and global max against PyTorch's choices; where they differ only at
  // near-ties, PyTorch's are taken (GroupPool::set_argmax) so the backward routes as its did.
  auto check_maxima = [&](const std::string& what) {
    auto& emb = net.feature_embedding();
    const auto their_graph = fx.at(what + "/feature_graph").template to_vector<std::int64_t>();
    for (Index b = 0; b < emb.blocks(); ++b) {
      auto& block = emb.block(b);
      const std::string id = "/" + std::to_string(b);
      struct Pool {
        std::string name;
        nn::GroupPool<S>& pool;
        const Matrix<S>& values;
        Index group_size, n;
        bool by_neighbour;  ///< edges of block 1's graph, whose rows PyTorch may order otherwise
      };
      for (const Pool& p : {Pool{"edge_argmax", block.edge_conv().max_pool(), block.edge_conv().edge_values(), block.edge_conv().k(), N, b == 1},
                            Pool{"global_argmax", block.global_max(), block.edge_output(), N, 1, false}}) {
        typename nn::GroupPool<S>::ArgmaxIndices theirs;
        const MaxAgreement a = max_agreement(p.values, p.group_size, p.pool.argmax(),
                                             fx.at(what + "/" + p.name + id).template to_vector<std::int64_t>(), p.n, tol, theirs,
                                             p.by_neighbour ? std::optional{std::pair{&block.edge_conv().graph(), &their_graph}} : std::nullopt);
        rep.j[what + "/" + p.name][std::to_string(b)] = {{"equal", a.equal}, {"tied", a.tied}, {"differ", a.differ}};
        if (a.differ) rep.fail(what + "/" + p.name + id);
        if (a.tied) p.pool.set_argmax(theirs);
      }
    }
  };
  net.forward(exec::seq, nn::Mode::eval, ldx, pred);
  if (check_graph("eval")) net.forward(exec::seq, nn::Mode::eval, ldx, pred);
  check_maxima("eval");
  rep.compare("eval/z_lr", net.code(), as_matrix<S>(fx.at("eval/z_lr"), net.latent_dim()));
  rep.compare("eval/up_weights", net.upsampling().weights(), as_matrix<S>(fx.at("eval/up_weights"), net.config().up_k).topRows(M));
  rep.compare("eval/z_hr", net.hr_code(), as_matrix<S>(fx.at("eval/z_hr"), net.latent_dim()));
  rep.compare("eval/hdx_pred", pred, as_matrix<S>(fx.at("eval/hdx_pred"), 3));
  net.prepare_inference(exec::seq);
  net.infer(exec::seq, ldx, pred_inf);
  rep.compare("infer/hdx_pred", pred_inf, as_matrix<S>(fx.at("eval/hdx_pred"), 3));
  {
    nn::SuperResolutionLoss<S> loss(net.config(), net.hr_rest_normalized(), data.hr_faces);
    const auto t = loss.evaluate(exec::seq, pred, hdx, net.code(), 0, nullptr, nullptr);
    rep.scalar("eval/loss_recon", t.recon, fx.at("eval/loss_recon").item<double>());
    rep.scalar("eval/loss_z_reg", t.z_reg, fx.at("eval/loss_z_reg").item<double>());
    rep.scalar("eval/loss_face_normals", t.face_normals, fx.at("eval/loss_face_normals").item<double>());
    rep.scalar("eval/loss_total", t.total, fx.at("eval/loss_total").item<double>());
  }

  // one training step from the exported state (repeated from that state with PyTorch's graph
  // where the train-mode graphs differ only at near-ties: the forward moves BatchNorm's statistics)
  const io::NpzArrays start = io::read_npz(state);
  nn::SuperResolutionLoss<S> loss(net.config(), net.hr_rest_normalized(), data.hr_faces);
  nn::Adam<S> adam(net.store(), {.lr = net.config().lr});
  Matrix<S> d_pred, d_z;
  edge1.use_dynamic_graph(N);
  auto train_forward = [&] {
    nn::load_state(net.store(), start);
    net.parameters_changed();
    net.forward(exec::omp, nn::Mode::train, ldx, pred);
  };
  train_forward();
  if (check_graph("train")) train_forward();
  check_maxima("train");
  net.store().zero_grad();
  const auto t = loss.evaluate(exec::omp, pred, hdx, net.code(), 0, &d_pred, &d_z);
  net.backward(exec::omp, d_pred, &d_z);
  rep.compare("train/z_lr", net.code(), as_matrix<S>(fx.at("train/z_lr"), net.latent_dim()));
  rep.compare("train/up_weights", net.upsampling().weights(), as_matrix<S>(fx.at("train/up_weights"), net.config().up_k).topRows(M));
  rep.compare("train/hdx_pred", pred, as_matrix<S>(fx.at("train/hdx_pred"), 3));
  rep.scalar("train/loss_recon", t.recon, fx.at("train/loss_recon").item<double>());
  rep.scalar("train/loss_z_reg", t.z_reg, fx.at("train/loss_z_reg").item<double>());
  rep.scalar("train/loss_face_normals", t.face_normals, fx.at("train/loss_face_normals").item<double>());
  rep.scalar("train/loss_total", t.total, fx.at("train/loss_total").item<double>());
  // per-tensor comparison of a span of the store against the fixture `prefix + name`
  auto compare_tensor = [&](const std::string& prefix, const std::string& name, std::span<const S> ours) {
    const auto ref = fx.at(prefix + name).template to_vector<S>();
    Report one;
    one.tol = grad_tol;
    one.floor = sizeof(S) == 4 ? 1e-6 : 1e-12;
    one.compare(name, Eigen::Map<const nn::Vector<S>>(ours.data(), Index(ours.size())), Eigen::Map<const nn::Vector<S>>(ref.data(), Index(ref.size())));
    return std::pair{one.j[name], one.ok};
  };
  double worst_grad = 0, worst_after = 0;
  std::string worst_name;
  const std::optional<io::NpzArrays> exact = reference_io.empty() ? std::nullopt : std::optional<io::NpzArrays>(io::read_npz(reference_io));
  for (const auto& e : net.store().entries()) {
    if (e.kind != nn::TensorEntry::Kind::parameter) continue;
    auto [r, ok] = compare_tensor("train/grad/", e.name, net.store().gradient(e));
    if (!ok && exact) {  // held to PyTorch's float64 gradient, within PyTorch's own float32 error (see above)
      const auto ours = net.store().gradient(e);
      const auto torch32 = fx.at("train/grad/" + e.name).template to_vector<S>();
      const auto torch64 = exact->at("train/grad/" + e.name).template to_vector<double>();
      double e_ours = 0, e_torch = 0, scale = 0;
      if (torch64.size() == ours.size() && torch32.size() == ours.size())
        for (std::size_t i = 0; i < ours.size(); ++i) {
          e_ours = std::max(e_ours, std::abs(double(ours[i]) - torch64[i]));
          e_torch = std::max(e_torch, std::abs(double(torch32[i]) - torch64[i]));
          scale = std::max(scale, std::abs(torch64[i]));
        }
      ok = torch64.size() == ours.size() && e_ours <= std::max(grad_tol * scale, 2 * e_torch);
      r["vs_float64"] = {{"ours", e_ours}, {"torch_float32", e_torch}, {"scale", scale}, {"ok", ok}};
      rep.j["train/grad_held_to_float64"].push_back(e.name);
    }
    if (!ok) rep.fail("train/grad/" + e.name);
    rep.j["train/grad"][e.name] = r;
    if (r.value("rel", 1.0) > worst_grad) worst_grad = r.value("rel", 1.0), worst_name = e.name;
  }
  rep.j["train/grad_worst"] = {{"name", worst_name}, {"rel", worst_grad}};
  adam.step(exec::omp);
  // Adam's first update is lr·g/(|g| + eps), about lr·sign(g): where float32 rounding leaves a
  // gradient entry at noise level (the BatchNorm-projected layers above) its sign, hence the
  // update, may flip. So in float32 a parameter after the step is held to that bound, |Δ| ≤ 2·lr,
  // plus the float32 rounding of the weights themselves (tol·max|w|: a flipped step on a weight
  // of size 4 adds an ulp of 4.8e-7 to 2·lr = 4e-4, which a bare 2·lr·(1 + 1e-3) did not allow);
  // buffers (BatchNorm running statistics) are not stepped and are held to tol relative. The
  // float64 run holds everything to grad_tol (relative), which proves the step itself.
  const bool float_run = sizeof(S) == 4;
  const double lr = net.config().lr;
  for (const auto& e : net.store().entries()) {
    const auto [r, rel_ok] = compare_tensor("train/after/", e.name, std::as_const(net.store()).values(e));
    const bool stepped = e.kind == nn::TensorEntry::Kind::parameter;
    const double bound = (stepped ? 2 * lr : 0.0) + tol * r.value("scale", 0.0);
    const bool ok = float_run ? r.value("max_abs", 1.0) <= bound : rel_ok;
    if (!ok) {
      rep.fail("train/after/" + e.name);
      rep.j["train/after_failed"][e.name] = r;
    }
    const double measure = float_run ? (stepped ? r.value("max_abs", 1.0) / bound : 0.0) : r.value("rel", 1.0);
    if (measure > worst_after) worst_after = measure, rep.j["train/after_worst"] = {{"name", e.name}, {"entry", r}};
  }
  rep.j["train/after_worst_rel"] = worst_after;  // float32: max |Δ| / its bound; float64: relative
  rep.j["ok"] = rep.ok;
  rep.j["failed"] = rep.failed;
  std::cout << rep.j.dump(1) << "\n";
  return rep.ok ? 0 : 1;
}

}  // namespace

int main(int argc, char** argv) {
  std::string model, state, iofile, data_dir, dtype = "float32", reference_io;
  double tol = 1e-5, grad_tol = -1;
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string k = argv[i], v = argv[i + 1];
    if (k == "--model") model = v;
    else if (k == "--state") state = v;
    else if (k == "--io") iofile = v;
    else if (k == "--data-dir") data_dir = v;
    else if (k == "--tol") tol = std::stod(v);
    else if (k == "--grad-tol") grad_tol = std::stod(v);
    else if (k == "--dtype") dtype = v;
    else if (k == "--reference-io") reference_io = v;
    else {
      std::cerr << "interop_check: unknown option " << k << "\n";
      return 2;
    }
  }
  if (model.empty() || state.empty() || iofile.empty() || data_dir.empty()) {
    std::cerr << "usage: interop_check --model MODEL.npz --state state_dict.npz --io io.npz --data-dir BUNNY [--tol 1e-5] [--grad-tol T] "
                 "[--dtype float32|float64] [--reference-io FLOAT64_IO.npz]\n";
    return 2;
  }
  try {
    if (dtype == "float32") return check<float>(model, state, iofile, data_dir, tol, grad_tol < 0 ? tol : grad_tol, reference_io);
    if (dtype == "float64") return check<double>(model, state, iofile, data_dir, tol, grad_tol < 0 ? tol : grad_tol);
    std::cerr << "interop_check: --dtype float32|float64\n";
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "interop_check: " << e.what() << "\n";
    return 1;
  }
}
