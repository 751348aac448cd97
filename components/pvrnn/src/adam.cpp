#include "dyad/pvrnn/adam.hpp"

#include <cmath>
#include <sstream>

namespace dyad::pvrnn {

Status AdamOptions::Validate() const {
  auto bad = [](const char* field, double v, const char* rule) {
    std::ostringstream s;
    s << "adam." << field << " = " << v << ": " << rule;
    return Status::InvalidArgument(s.str());
  };
  if (!(lr > 0)) return bad("lr", lr, "must be > 0");
  if (!(beta1 >= 0 && beta1 < 1)) return bad("beta1", beta1, "must be in [0, 1)");
  if (!(beta2 >= 0 && beta2 < 1)) return bad("beta2", beta2, "must be in [0, 1)");
  if (!(epsilon > 0)) return bad("epsilon", epsilon, "must be > 0");
  return Status::OK();
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
