#pragma once
/// \file
/// Face-normal cosine loss (paper Eq. 5): for every triangle of the HR surface, 1 − the cosine
/// between the normal of the predicted shape and the normal of the target shape. Eq. 5 sums over
/// the triangles; the official PyTorch code takes the mean (both are offered, mean by default).
///
///     nn::FaceNormalLoss<float> fn(rest, faces);                       // rest M×3, faces F×3 (once)
///     double l = fn.value_and_gradient(exec::omp, pred, target, &d_pred, 0.1);
///     // pred, target: (B·M)×3 displacements; d_pred = 0.1·∂l/∂pred

#include <cmath>
#include <string>
#include <type_traits>
#include <Eigen/Geometry>

#include "graph_features.hpp"
#include "tensor.hpp"

namespace simsr::nn {

/// How a loss combines its per-element terms: the sum (as the paper writes Eq. 5) or the mean
/// (what the official code computes).
enum class Reduction { mean, sum };

/// Face-normal loss of paper Eq. 5 over a fixed HR triangle mesh. Positions of batch item b are
/// rest + displacement (row b·M + v of pred/target is vertex v of item b); the normal of triangle
/// (a, b, c) is the unnormalized n = (b − a) × (c − a) (the cosine normalizes). The loss is
///
///     L = Σ_{items, triangles} (1 − cos(n_pred, n_true))       (Reduction::sum, Eq. 5)
///     L = that sum / (B·F)                                     (Reduction::mean, official code)
///
/// The cosine mirrors `torch.nn.functional.cosine_similarity(x, y, eps=1e-8)` as torch 1.13 (the
/// version checked, Debian python3-torch 1.13.0a0) computes it — which is NOT the formula of its
/// documentation, (x·y) / max(‖x‖·‖y‖, eps). Torch 1.13 clamps each norm on its own,
///
///     n_x = sqrt(max(x·x, eps²)),  n_y = sqrt(max(y·y, eps²)),  cos = (x/n_x)·(y/n_y),
///
/// (x = (3e-9, 0, 0), y = (1000, 0, 0) gives 0.3, where the documented formula gives 1), and the
/// clamp is done in place under no_grad, so autograd differentiates n_x as if it were the plain
/// norm but with the clamped value: ∂n_x/∂x = x/n_x. Its gradient is therefore always
///
///     ∂cos/∂x = y/(n_x·n_y) − cos·x/n_x²,
///
/// which for ‖x‖ ≥ eps is the true derivative and below eps is torch's (checked: x = (1e-9, 0, 0),
/// y = (1, 0, 0) gives cos 0.1 and ∂cos/∂x_0 = 9.9e7, not the 1e8 of the clamped function).
/// Consequences on a mesh, both mirrored here:
///  - a predicted triangle of zero area (n_pred = 0): cos = 0, the term is 1, and the gradient of
///    its normal is −n̂_true/eps, i.e. a push of size 1e8·(edge length) that re-opens the triangle;
///  - a target triangle of zero area (n_true = 0): cos = 0, the term is 1 and contributes no
///    gradient at all (a constant).
/// Compared with torch 1.13 in float64 on an icosphere (B = 2, collapsed triangles included), the
/// terms agree to rounding except where two vertices coincide: this cross product gives exactly 0,
/// torch.cross a ~1e-17 residue (its kernel rounds differently), so there cos is 0 here and
/// ~1e-10 in torch — both far below eps, where the cosine is meaningless anyway.
///
/// The gradient w.r.t. pred only (the target is data). By the chain rule through the cross
/// product, the corner k of a triangle with gradient g = ∂L/∂n receives g × (p_{k+2} − p_{k+1})
/// (corners cyclic). The value is summed in double over fixed chunks of triangles; the gradient is
/// gathered per vertex over a precomputed vertex → (triangle, corner) adjacency in ascending
/// triangle order (no atomics): exec::seq and exec::omp agree bit for bit. Everything is computed
/// in double and rounded to S once. Warm calls (same B) allocate nothing.
template <class S = float>
class FaceNormalLoss {
 public:
  using scalar_type = S;
  using Faces = Eigen::Matrix<VIndex, Eigen::Dynamic, 3, Eigen::RowMajor>;

  /// rest: M×3 HR rest positions; faces: F×3 vertex indices (simsr::Tris or any integer matrix).
  /// ShapeError for the wrong number of columns, ArgumentError for M < 1, F < 1, an index outside
  /// [0, M) (naming the triangle), or eps ≤ 0.
  template <class DR, class DF>
  FaceNormalLoss(const Eigen::MatrixBase<DR>& rest, const Eigen::MatrixBase<DF>& faces, Reduction reduction = Reduction::mean,
                 double eps = 1e-8)
      : reduction_(reduction), eps_(eps) {
    static_assert(std::is_integral_v<typename DF::Scalar>, "nn::FaceNormalLoss: faces must hold integer vertex indices");
    detail::check_shape("nn::FaceNormalLoss", "rest positions", rest, -1, 3);
    detail::check_shape("nn::FaceNormalLoss", "faces", faces, -1, 3);
    if (rest.rows() < 1 || faces.rows() < 1) throw ArgumentError("nn::FaceNormalLoss: needs at least one vertex and one triangle");
    if (!(eps > 0) || !std::isfinite(eps)) throw ArgumentError("nn::FaceNormalLoss: eps = " + std::to_string(eps) + " must be positive");
    const Index M = rest.rows();
    for (Index t = 0; t < faces.rows(); ++t)
      for (Index k = 0; k < 3; ++k) {
        const auto v = faces(t, k);
        if (v < 0 || Index(v) >= M)
          throw ArgumentError("nn::FaceNormalLoss: triangle " + std::to_string(t) + " corner " + std::to_string(k) + ": vertex " +
                              std::to_string(v) + " is outside [0, " + std::to_string(M) + ")");
      }
    rest_ = rest.template cast<double>();
    faces_ = faces.template cast<VIndex>();
    // e = t·3 + k is corner k of triangle t; its target is the vertex there.
    corners_.build(M, faces_.size(), [&](Index e) { return Index(faces_.data()[e]); });
  }

  Index vertices() const { return rest_.rows(); }
  Index triangles() const { return faces_.rows(); }
  Reduction reduction() const { return reduction_; }
  double eps() const { return eps_; }
  const Faces& faces() const { return faces_; }

  /// The loss of pred against target ((B·M)×3 displacements each, B ≥ 1; an nn::Matrix<S> or a
  /// block of one is read in place, another matrix type is copied); with `d_pred`, also
  /// d_pred = scale·∂L/∂pred ((B·M)×3, resized only when the shape changes). ShapeError for wrong
  /// shapes; ArgumentError when d_pred aliases pred or target.
  template <exec::HostPolicy Policy>
  double value_and_gradient(Policy policy, const ConstView<S>& pred, const ConstView<S>& target, Matrix<S>* d_pred = nullptr,
                            double scale = 1.0) {
    const Index M = rest_.rows(), F = faces_.rows();
    if (pred.cols() != 3 || pred.rows() < 1 || pred.rows() % M)
      throw ShapeError("nn::FaceNormalLoss: predicted displacements (B·M rows, M = " + std::to_string(M) + ")", {-1, 3},
                       {pred.rows(), pred.cols()});
    detail::check_shape("nn::FaceNormalLoss", "target displacements", target, pred.rows(), 3);
    if (d_pred && (inside(pred.data(), *d_pred) || inside(target.data(), *d_pred)))
      throw ArgumentError("nn::FaceNormalLoss: the gradient d_pred must not alias pred or target (they lie in its storage)");
    const Index B = pred.rows() / M, T = B * F;
    const double norm = reduction_ == Reduction::mean ? double(T) : 1.0, g_scale = scale / norm;
    if (d_pred) ensure_shape(g_, T, 3);

    // pass 1: per triangle (item-major), the term 1 − cos and the normal's gradient g.
    const Index nc = exec::chunk_count(T, exec::default_chunks), workers = exec::worker_count(policy, nc);
    double parts[exec::default_chunks];
    const double eps2 = eps_ * eps_;
    exec::for_chunks(policy, T, nc, workers, [&](Index, Index c, Index begin, Index end) {
      double s = 0;
      for (Index i = begin; i < end; ++i) {
        const Index item = i / F, t = i % F;
        const V3 x = normal(pred, item, t), y = normal(target, item, t);
        const double nx = std::sqrt(std::max(x.squaredNorm(), eps2)), ny = std::sqrt(std::max(y.squaredNorm(), eps2));
        const double cosine = x.dot(y) / (nx * ny);
        s += 1.0 - cosine;
        // ∂(1 − cos)/∂x, torch's form (see the class comment)
        if (d_pred) g_.row(i) = (g_scale * (cosine / (nx * nx) * x - y / (nx * ny))).transpose();
      }
      parts[c] = s;
    });
    double total = 0;
    for (Index c = 0; c < nc; ++c) total += parts[c];

    // pass 2: per vertex of each item, Σ over its corners (ascending triangle) of g × opposite edge.
    if (d_pred) {
      ensure_shape(*d_pred, B * M, 3);
      const Index rows = B * M;
      const Index vc = exec::chunk_count(rows, product_chunks), vworkers = exec::worker_count(policy, vc);
      exec::for_chunks(policy, rows, vc, vworkers, [&](Index, Index, Index begin, Index end) {
        for (Index r = begin; r < end; ++r) {
          const Index item = r / M, v = r % M;
          V3 acc = V3::Zero();
          for (Index s = corners_.start[std::size_t(v)]; s < corners_.start[std::size_t(v + 1)]; ++s) {
            const Index e = corners_.edges[std::size_t(s)], t = e / 3, k = e % 3;
            const V3 g = g_.row(item * F + t).transpose();
            acc += g.cross(position(pred, item, faces_(t, (k + 2) % 3)) - position(pred, item, faces_(t, (k + 1) % 3)));
          }
          for (Index j = 0; j < 3; ++j) (*d_pred)(r, j) = static_cast<S>(acc[j]);
        }
      });
    }
    return total / norm;
  }


 private:
  using V3 = Eigen::Matrix<double, 3, 1>;

  static bool inside(const S* p, const Matrix<S>& m) { return p >= m.data() && p < m.data() + m.size(); }
  /// rest + displacement of vertex v in batch item `item`, in double.
  V3 position(const ConstView<S>& disp, Index item, Index v) const {
    const Index r = item * rest_.rows() + v;
    return V3(rest_(v, 0) + double(disp(r, 0)), rest_(v, 1) + double(disp(r, 1)), rest_(v, 2) + double(disp(r, 2)));
  }
  /// (b − a) × (c − a) of triangle t of batch item `item`.
  V3 normal(const ConstView<S>& disp, Index item, Index t) const {
    const V3 a = position(disp, item, faces_(t, 0));
    return (position(disp, item, faces_(t, 1)) - a).cross(position(disp, item, faces_(t, 2)) - a);
  }

  Reduction reduction_;
  double eps_;
  Matrix<double> rest_;              ///< M×3
  Faces faces_;                      ///< F×3
  detail::ReverseAdjacency corners_; ///< vertex → corners e = t·3 + k, ascending e
  Matrix<double> g_;                 ///< (B·F)×3 workspace: scale·∂L/∂n_pred of the last call
};

}  // namespace simsr::nn
