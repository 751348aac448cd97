// Internal: one time step of the stacked network for a block of columns. Shared by the
// posterior pass (training, error regression) and the prior generator so both run the same code.
#pragma once

#include <cmath>

#include "dyad/pvrnn/parameters.hpp"

namespace dyad::pvrnn::internal {

template <typename Scalar>
using Out = Eigen::Ref<MatrixT<Scalar>>;
template <typename Scalar>
using In = Eigen::Ref<const MatrixT<Scalar>>;

// Per-row leak rate a = 1/tau of the stacked state and its complement 1 - a, in Scalar.
template <typename Scalar>
void LeakRates(const NetworkLayout& layout, VectorT<Scalar>* rate, VectorT<Scalar>* keep) {
  const int td = layout.total_d();
  rate->resize(td);
  keep->resize(td);
  for (int i = 0; i < td; ++i) {
    (*rate)[i] = static_cast<Scalar>(layout.rate()[i]);
    (*keep)[i] = Scalar(1) - (*rate)[i];
  }
}

// Where z comes from in this step.
enum class Source { kPosterior, kPrior };

// pre = R d_prev + b; fills mu/logsigma of prior and posterior (posterior adds A), z and the new
// h, d. `a_mu`/`a_ls` are read only for Source::kPosterior. No allocation.
template <typename Scalar, typename RMat, typename BVec, typename WzMat>
inline void StepForward(const RMat& r, const BVec& rbias, const WzMat& wz, const VectorT<Scalar>& rate,
                        const VectorT<Scalar>& keep, int total_d, int total_z, Source source,
                        In<Scalar> d_prev, In<Scalar> h_prev, In<Scalar> a_mu, In<Scalar> a_ls,
                        In<Scalar> eps, Out<Scalar> pre, Out<Scalar> mu_p, Out<Scalar> ls_p,
                        Out<Scalar> sig_p, Out<Scalar> mu_q, Out<Scalar> ls_q, Out<Scalar> sig_q,
                        Out<Scalar> z, Out<Scalar> h, Out<Scalar> d) {
  // One column (online regression, generation): GEMV, whose independent accumulators beat the
  // lazy product's single FMA chain (measured 1.4x on 70x50 float); several: the lazy product.
  if (d_prev.cols() == 1)
    pre.col(0).noalias() = r * d_prev.col(0);
  else
    pre.noalias() = r.lazyProduct(d_prev);
  pre.colwise() += rbias;
  const int zp = total_d, zlp = total_d + total_z, zq = total_d + 2 * total_z,
            zlq = total_d + 3 * total_z;
  mu_p = pre.middleRows(zp, total_z).array().tanh().matrix();
  ls_p = pre.middleRows(zlp, total_z);
  sig_p = ls_p.array().exp().matrix();
  if (source == Source::kPosterior) {
    mu_q = (pre.middleRows(zq, total_z) + a_mu).array().tanh().matrix();
    ls_q = pre.middleRows(zlq, total_z) + a_ls;
    sig_q = ls_q.array().exp().matrix();
    z = (mu_q.array() + sig_q.array() * eps.array()).matrix();
  } else {
    z = (mu_p.array() + sig_p.array() * eps.array()).matrix();
  }
  auto u = pre.topRows(total_d);
  if (z.cols() == 1)
    u.col(0).noalias() += wz * z.col(0);
  else
    u.noalias() += wz.lazyProduct(z);
  h = ((h_prev.array().colwise() * keep.array()) + (u.array().colwise() * rate.array())).matrix();
  d = h.array().tanh().matrix();
}

// In place on `x` (output_units x columns, logits on entry): the softmax of every DOF's block,
// column by column. Unless `log_x` is null, it receives log x (same shape). No allocation.
template <typename Scalar>
void SoftmaxPerDof(const NetworkLayout& layout, MatrixT<Scalar>& x, MatrixT<Scalar>* log_x) {
  for (int dof = 0; dof < layout.spec().num_dofs(); ++dof) {
    const int off = layout.output_offset(dof), n = layout.output_units(dof);
    for (int j = 0; j < x.cols(); ++j) {
      auto c = x.col(j).segment(off, n);
      c.array() -= c.maxCoeff();
      if (log_x != nullptr) log_x->col(j).segment(off, n) = c;
      c.array() = c.array().exp();
      const Scalar sum = c.sum();
      c /= sum;
      if (log_x != nullptr) log_x->col(j).segment(off, n).array() -= std::log(sum);
    }
  }
}

}  // namespace dyad::pvrnn::internal
