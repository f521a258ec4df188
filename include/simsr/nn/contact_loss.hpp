#pragma once
/// \file
/// A contact term for the training loss (issue #12 item 7; the core paper's §6.1 names lip
/// penetration as future work): two patches of the predicted surface — the upper and the lower
/// lip — must not pass through each other. The LR simulation has no lip contact (§4), so a
/// network that learns from it can predict lips that cross where the HR truth holds them apart.
///
///     nn::ContactLoss<float> contact(rest, patches, radius, margin);   // rest M×3, once
///     double l = contact.value_and_gradient(exec::omp, pred, &d_pred, w);   // adds w·∂l/∂pred
///
/// Candidates are fixed at rest: a vertex v of one patch against a triangle t of the other, when
/// the point–triangle distance is below `radius` and v lies on t's outer side (the signed distance
/// s = (x_v − x_0)·n̂ of v from t's plane is positive; n̂ = (x_1 − x_0) × (x_2 − x_0) normalized,
/// outward on a consistently oriented surface). Each pair asks for a clearance
/// m = min(margin, s_rest / 2), as the simulator's lip contact does, so lips that nearly touch at
/// rest are not pushed apart there. For a prediction the pair is active where v projects into t
/// (all barycentric coordinates of its foot ≥ 0), −radius < s < m, and adds (m − s)²:
///
///     L = (1/B) Σ_items Σ_active pairs (m − s)²          (prediction units: the network's)
///
/// The radius is also the depth band: a vertex further behind a triangle than that is not taken
/// as through it. On a curved body (a lip's radius of curvature is a few millimetres) the prism
/// behind a triangle leaves the body a few millimetres deep, so a wide band counts vertices that
/// are merely beside the other lip: on the face's network predictions a 15 mm radius found
/// penetrating pairs in 119 of 240 frames, 5 mm in 76, while the truth has none at either.
///
/// The gradient is exact on the active set (the normal's rotation included):
///     ∂s/∂x_v = n̂,  ∂s/∂x_1 = e₂ × q,  ∂s/∂x_2 = q × e₁,  ∂s/∂x_0 = −n̂ − e₂ × q − q × e₁,
/// with e₁ = x_1 − x_0, e₂ = x_2 − x_0, q = (I − n̂n̂ᵀ)(x_v − x_0)/‖e₁ × e₂‖. The active set changes
/// where a vertex's foot crosses a triangle edge; there the neighbouring triangle (nearly coplanar
/// on a smooth surface) takes over with a nearly equal s.
///
/// Items run in parallel, each item's pairs in order, so exec::seq and exec::omp agree bit for bit.

#include <algorithm>
#include <array>
#include <cmath>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "../core/error.hpp"
#include "../core/parallel.hpp"
#include "../core/types.hpp"
#include "../mesh/closest_point.hpp"
#include "../mesh/contact_patches.hpp"
#include "graph_features.hpp"
#include "tensor.hpp"

namespace simsr::nn {

/// A candidate of ContactLoss: vertex `vertex` against triangle `tri` of the other patch, with
/// the clearance `margin` (prediction units).
struct ContactPair {
  Index vertex = 0;
  std::array<Index, 3> tri{};
  double margin = 0;
};

template <class S = float>
class ContactLoss {
 public:
  using scalar_type = S;

  /// rest: M×3 rest positions in the predictions' units (their rows are the surface vertices the
  /// patches index); radius > 0 and margin ≥ 0 in the same units. ArgumentError for an index
  /// outside [0, M), a vertex in both patches, an empty patch (ContactPatches::check) or a bad
  /// radius or margin; ShapeError for rest not M×3.
  template <class DR>
  ContactLoss(const Eigen::MatrixBase<DR>& rest, const ContactPatches& patches, double radius, double margin) : radius_(radius) {
    detail::check_shape("nn::ContactLoss", "rest positions", rest, -1, 3);
    if (!(radius > 0) || !std::isfinite(radius)) throw ArgumentError("nn::ContactLoss: radius = " + std::to_string(radius) + " must be positive");
    if (!(margin >= 0) || !std::isfinite(margin)) throw ArgumentError("nn::ContactLoss: margin = " + std::to_string(margin) + " must be >= 0");
    m_ = rest.rows();
    const std::vector<char> side = patches.check(m_, "nn::ContactLoss");  // 1: patch a, 2: patch b
    const Matrix<double> X = rest.template cast<double>();
    if (!X.allFinite()) throw ArgumentError("nn::ContactLoss: the rest positions are not finite");
    const Tris* sets[2] = {&patches.a, &patches.b};
    // Every vertex of one patch against every triangle of the other (once, at rest).
    for (int s = 0; s < 2; ++s) {
      const Tris& other = *sets[1 - s];
      for (Index v = 0; v < m_; ++v) {
        if (side[std::size_t(v)] != s + 1) continue;
        const V3 p = X.row(v).transpose();
        for (Index t = 0; t < other.rows(); ++t) {
          const V3 x0 = X.row(other(t, 0)).transpose(), x1 = X.row(other(t, 1)).transpose(), x2 = X.row(other(t, 2)).transpose();
          const V3 c = (x1 - x0).cross(x2 - x0);
          const double area2 = c.norm();
          if (!(area2 > 0)) continue;  // a degenerate triangle has no side
          const V3 w = closest_point_on_triangle<double>(p, x0, x1, x2);
          if ((w[0] * x0 + w[1] * x1 + w[2] * x2 - p).norm() >= radius) continue;
          const double s_rest = (p - x0).dot(c) / area2;
          if (!(s_rest > 0)) continue;
          pairs_.push_back({v, {Index(other(t, 0)), Index(other(t, 1)), Index(other(t, 2))}, std::min(margin, 0.5 * s_rest)});
        }
      }
    }
    rest_ = X;
  }

  Index vertices() const { return m_; }
  /// The candidate pairs found at rest.
  const std::vector<ContactPair>& pairs() const { return pairs_; }
  double radius() const { return radius_; }
  /// Active pairs of the last value_and_gradient call with s < 0 (the vertex behind the other
  /// patch's triangle: penetration), summed over its items.
  Index penetrating() const { return penetrating_; }
  /// Active pairs of the last call (those that added to L), summed over its items.
  Index active() const { return active_; }

  /// L for pred ((B·M)×3 displacements from rest); with d_pred ((B·M)×3), adds scale·∂L/∂pred to it.
  template <exec::HostPolicy Policy>
  double value_and_gradient(Policy policy, const ConstView<S>& pred, Matrix<S>* d_pred = nullptr, double scale = 1.0) {
    if (pred.cols() != 3 || pred.rows() < 1 || pred.rows() % m_)
      throw ShapeError("nn::ContactLoss: predicted displacements (B·M rows, M = " + std::to_string(m_) + ")", {-1, 3}, {pred.rows(), pred.cols()});
    const Index B = pred.rows() / m_;
    if (d_pred) detail::check_shape("nn::ContactLoss", "gradient", *d_pred, pred.rows(), 3);
    if (Index(item_value_.size()) < B) {
      item_value_.resize(std::size_t(B));
      item_penetrating_.resize(std::size_t(B));
      item_active_.resize(std::size_t(B));
    }
    const double g_scale = scale / double(B);
    exec::parallel_for(policy, B, [&](Index item) {
      double value = 0;
      Index behind = 0, active = 0;
      auto x = [&](Index v) -> V3 {
        const Index r = item * m_ + v;
        return V3(rest_(v, 0) + double(pred(r, 0)), rest_(v, 1) + double(pred(r, 1)), rest_(v, 2) + double(pred(r, 2)));
      };
      for (const ContactPair& pr : pairs_) {
        const V3 p = x(pr.vertex), x0 = x(pr.tri[0]), x1 = x(pr.tri[1]), x2 = x(pr.tri[2]);
        const V3 e1 = x1 - x0, e2 = x2 - x0, c = e1.cross(e2);
        const double area2 = c.norm();
        if (!(area2 > 0)) continue;
        const V3 n = c / area2, r = p - x0;
        const double s = r.dot(n);
        if (!(s < pr.margin) || !(s > -radius_)) continue;
        // the foot r − s n in barycentrics: inside when all ≥ 0
        const V3 f = r - s * n;
        const double b1 = f.cross(e2).dot(n) / area2, b2 = e1.cross(f).dot(n) / area2;
        if (b1 < 0 || b2 < 0 || b1 + b2 > 1) continue;
        const double gap = pr.margin - s;
        value += gap * gap;
        ++active;
        if (s < 0) ++behind;
        if (d_pred) {
          const double ds = -2.0 * gap * g_scale;  // ∂(gap²)/∂s, scaled
          const V3 q = (r - s * n) / area2;
          const V3 g1 = e2.cross(q), g2 = q.cross(e1);
          add(*d_pred, item * m_ + pr.vertex, ds * n);
          add(*d_pred, item * m_ + pr.tri[1], ds * g1);
          add(*d_pred, item * m_ + pr.tri[2], ds * g2);
          add(*d_pred, item * m_ + pr.tri[0], ds * (-n - g1 - g2));
        }
      }
      item_value_[std::size_t(item)] = value;
      item_penetrating_[std::size_t(item)] = behind;
      item_active_[std::size_t(item)] = active;
    });
    double total = 0;
    penetrating_ = active_ = 0;
    for (Index b = 0; b < B; ++b) {
      total += item_value_[std::size_t(b)];
      penetrating_ += item_penetrating_[std::size_t(b)];
      active_ += item_active_[std::size_t(b)];
    }
    return total / double(B);
  }

 private:
  using V3 = Eigen::Matrix<double, 3, 1>;
  static void add(Matrix<S>& g, Index row, const V3& v) {
    for (Index k = 0; k < 3; ++k) g(row, k) += static_cast<S>(v[k]);
  }

  Index m_ = 0;
  double radius_ = 0;
  Matrix<double> rest_;
  std::vector<ContactPair> pairs_;
  std::vector<double> item_value_;
  std::vector<Index> item_penetrating_, item_active_;
  Index penetrating_ = 0, active_ = 0;
};

}  // namespace simsr::nn
