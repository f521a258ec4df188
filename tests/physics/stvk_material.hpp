#pragma once
// A test-only St. Venant–Kirchhoff material with an exact, independently derived ∂P/∂F, so the
// assembly code is tested apart from the library's own materials.
#include <simsr/physics/materials/material.hpp>

namespace simsr_test {

struct StVK {
  using scalar_type = double;
  using Element = simsr::physics::NoElementData;
  double mu = 1.0, lambda = 0.5;
  double energy(const Eigen::Matrix3d& F, const Element&) const {
    const Eigen::Matrix3d E = 0.5 * (F.transpose() * F - Eigen::Matrix3d::Identity());
    return mu * E.squaredNorm() + 0.5 * lambda * E.trace() * E.trace();
  }
  Eigen::Matrix3d stress(const Eigen::Matrix3d& F, const Element&) const {
    const Eigen::Matrix3d E = 0.5 * (F.transpose() * F - Eigen::Matrix3d::Identity());
    return F * (2 * mu * E + lambda * E.trace() * Eigen::Matrix3d::Identity());
  }
  simsr::physics::Mat9<> stress_derivative(const Eigen::Matrix3d& F, const Element&, simsr::physics::Definiteness) const {
    simsr::physics::Mat9<> A;
    const Eigen::Matrix3d E = 0.5 * (F.transpose() * F - Eigen::Matrix3d::Identity());
    const Eigen::Matrix3d Sm = 2 * mu * E + lambda * E.trace() * Eigen::Matrix3d::Identity();
    for (int c = 0; c < 9; ++c) {
      Eigen::Matrix3d dF = Eigen::Matrix3d::Zero();
      dF(c % 3, c / 3) = 1;
      const Eigen::Matrix3d dE = 0.5 * (dF.transpose() * F + F.transpose() * dF);
      const Eigen::Matrix3d dP = dF * Sm + F * (2 * mu * dE + lambda * dE.trace() * Eigen::Matrix3d::Identity());
      A.col(c) = Eigen::Map<const Eigen::Matrix<double, 9, 1>>(dP.data());
    }
    return A;
  }
};

}  // namespace simsr_test
