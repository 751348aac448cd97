// The numeric side of the gradient checks: central differences, h = 1e-6 (double).
#pragma once

#include <Eigen/Core>
#include <algorithm>

namespace dyad::pvrnn::testing {

// (loss(v + h) - loss(v - h)) / 2h for the number `v` that `loss` reads; `v` is restored.
template <typename Loss>
double CentralDifference(double& v, Loss&& loss, double h = 1e-6) {
  const double keep = v;
  v = keep + h;
  const double up = loss();
  v = keep - h;
  const double down = loss();
  v = keep;
  return (up - down) / (2 * h);
}

// |a - n| / (|a| + |n|): 0 when analytic and numeric gradients agree.
inline double RelativeError(const Eigen::VectorXd& analytic, const Eigen::VectorXd& numeric) {
  const double scale = std::max(analytic.norm() + numeric.norm(), 1e-300);
  return (analytic - numeric).norm() / scale;
}

}  // namespace dyad::pvrnn::testing
