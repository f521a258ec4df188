#pragma once
/// \file
/// Test helpers for EnergyTerms: dense Hessian assembly, central finite differences of the energy
/// and of the gradient, smallest eigenvalue.

#include <simsr/core/parallel.hpp>
#include <simsr/physics/energy_term.hpp>

#include <Eigen/Dense>
#include <algorithm>
#include <random>
#include <vector>

namespace simsr::test {

/// The assembled matrix of H as a dense 3n×3n matrix (row 3i + a: vertex i, coordinate a).
inline Eigen::MatrixXd dense_hessian(physics::BlockHessian<double>& H) {
  const std::vector<char> free(std::size_t(3 * H.num_vertices()), 0);
  return Eigen::MatrixXd(H.assemble(exec::seq, free));
}

/// The term's Hessian at x (its one add_hessian form, into a BlockHessian that grows to the
/// blocks it adds), dense.
template <class Term>
Eigen::MatrixXd assembled_hessian(const Term& t, const Points<>& x, physics::Definiteness d = physics::Definiteness::project) {
  physics::BlockHessian<double> H(x.rows());
  H.set_zero();
  t.add_hessian(exec::seq, x, H, d);
  return dense_hessian(H);
}

template <class Term>
Points<> gradient(const Term& t, const Points<>& x) {
  Points<> g = Points<>::Zero(x.rows(), 3);
  t.add_gradient(exec::seq, x, g);
  return g;
}

/// Central differences of the energy, step h: #V×3.
template <class Term>
Points<> fd_gradient(const Term& t, const Points<>& x, double h) {
  Points<> g(x.rows(), 3), y = x;
  for (Index i = 0; i < x.rows(); ++i)
    for (int a = 0; a < 3; ++a) {
      y(i, a) = x(i, a) + h;
      const double ep = t.energy(exec::seq, y);
      y(i, a) = x(i, a) - h;
      const double em = t.energy(exec::seq, y);
      y(i, a) = x(i, a);
      g(i, a) = (ep - em) / (2 * h);
    }
  return g;
}

/// Central differences of the gradient, step h: 3V×3V (column 3i + a: derivative along x(i, a)).
template <class Term>
Eigen::MatrixXd fd_hessian(const Term& t, const Points<>& x, double h) {
  const Index n = x.rows();
  Eigen::MatrixXd D(3 * n, 3 * n);
  Points<> y = x;
  for (Index i = 0; i < n; ++i)
    for (int a = 0; a < 3; ++a) {
      y(i, a) = x(i, a) + h;
      const Points<> gp = gradient(t, y);
      y(i, a) = x(i, a) - h;
      const Points<> gm = gradient(t, y);
      y(i, a) = x(i, a);
      const Points<> d = (gp - gm) / (2 * h);
      D.col(3 * i + a) = Eigen::Map<const Eigen::VectorXd>(d.data(), 3 * n);  // row-major: 3j + b
    }
  return D;
}

inline double min_eigenvalue(const Eigen::MatrixXd& H) {
  if (H.size() == 0) return 0;
  return Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>((H + H.transpose()) / 2, Eigen::EigenvaluesOnly).eigenvalues().minCoeff();
}

/// Max-abs error relative to max(1, max-abs of the reference).
template <class A, class B>
double rel_error(const A& got, const B& ref) {
  return (got - ref).cwiseAbs().maxCoeff() / std::max(1.0, ref.cwiseAbs().maxCoeff());
}

template <class Rng>
Points<> random_points(Index n, double lo, double hi, Rng& rng) {
  std::uniform_real_distribution<double> u(lo, hi);
  Points<> P(n, 3);
  for (Index i = 0; i < n; ++i)
    for (int a = 0; a < 3; ++a) P(i, a) = u(rng);
  return P;
}

}  // namespace simsr::test
