#include "dyad/pvrnn/adam.hpp"

#include <cmath>
#include <sstream>

namespace dyad::pvrnn {

std::vector<FieldProblem> AdamOptions::Problems() const {
  std::vector<FieldProblem> out;
  auto check = [&out](bool ok, const char* field, double v, const char* rule) {
    if (ok) return;
    std::ostringstream s;
    s << rule << ", got " << v;
    out.push_back({std::string("adam.") + field, s.str()});
  };
  check(std::isfinite(lr) && lr > 0, "lr", lr, "must be finite and > 0");
  check(beta1 >= 0 && beta1 < 1, "beta1", beta1, "must be in [0, 1)");
  check(beta2 >= 0 && beta2 < 1, "beta2", beta2, "must be in [0, 1)");
  check(std::isfinite(epsilon) && epsilon > 0, "epsilon", epsilon, "must be finite and > 0");
  return out;
}

Status AdamOptions::Validate() const {
  const std::vector<FieldProblem> p = Problems();
  return p.empty() ? Status::OK() : Status::InvalidArgument(p.front().ToString());
}

template <typename Scalar>
Adam<Scalar>::Adam(int size, const AdamOptions& options)
    : options_(options), m_(VectorT<Scalar>::Zero(size)), v_(VectorT<Scalar>::Zero(size)) {}

template <typename Scalar>
void Adam<Scalar>::Step(VectorT<Scalar>& params, const VectorT<Scalar>& grads) {
  ++step_;
  const Scalar b1 = static_cast<Scalar>(options_.beta1), b2 = static_cast<Scalar>(options_.beta2);
  // Bias corrections folded into the step size and epsilon (one pass over the vector).
  const double c1 = 1.0 - std::pow(options_.beta1, static_cast<double>(step_));
  const double c2 = 1.0 - std::pow(options_.beta2, static_cast<double>(step_));
  const Scalar step_size = static_cast<Scalar>(options_.lr * std::sqrt(c2) / c1);
  const Scalar eps_hat = static_cast<Scalar>(options_.epsilon * std::sqrt(c2));
  m_.array() = b1 * m_.array() + (Scalar(1) - b1) * grads.array();
  v_.array() = b2 * v_.array() + (Scalar(1) - b2) * grads.array().square();
  params.array() -= step_size * m_.array() / (v_.array().sqrt() + eps_hat);
}

template class Adam<float>;
template class Adam<double>;

}  // namespace dyad::pvrnn
