// dyad/pvrnn/adam.hpp: the Adam optimiser over a flat parameter vector (Kingma & Ba, with bias
// correction, as NRL). No allocation per step.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "dyad/pvrnn/parameters.hpp"
#include "dyad/status.hpp"

namespace dyad::pvrnn {

struct AdamOptions {
  double lr = 0.001;      // step size alpha; REQUIRES finite, > 0
  double beta1 = 0.9;     // REQUIRES in [0, 1)
  double beta2 = 0.999;   // REQUIRES in [0, 1)
  double epsilon = 1e-8;  // added to sqrt(v_hat); REQUIRES finite, > 0
  // Every broken constraint ("adam.lr": "must be finite and > 0, got 0"); Validate: the first.
  std::vector<FieldProblem> Problems() const;
  Status Validate() const;
};

template <typename Scalar>
class Adam {
 public:
  Adam(int size, const AdamOptions& options);
  // params -= lr * m_hat / (sqrt(v_hat) + epsilon); `step` counts from 1.
  void Step(VectorT<Scalar>& params, const VectorT<Scalar>& grads);
  int64_t step() const { return step_; }
  void set_step(int64_t step) { step_ = step; }
  VectorT<Scalar>& m() { return m_; }
  VectorT<Scalar>& v() { return v_; }
  const VectorT<Scalar>& m() const { return m_; }
  const VectorT<Scalar>& v() const { return v_; }

 private:
  AdamOptions options_;
  int64_t step_ = 0;
  VectorT<Scalar> m_, v_;
};

}  // namespace dyad::pvrnn
