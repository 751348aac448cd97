// Internal: one time step of the stacked network for a block of columns. Shared by the
// posterior pass (training, error regression) and the prior generator so both run the same code.
#pragma once

#include <cmath>
#include <type_traits>

#include "dyad/pvrnn/parameters.hpp"
#include "small_product.hpp"

namespace dyad::pvrnn::internal {

template <typename Scalar>
using Out = Eigen::Ref<MatrixT<Scalar>>;
template <typename Scalar>
using In = Eigen::Ref<const MatrixT<Scalar>>;

// Whole columns (contiguous in memory), viewed as one flat array.
template <typename Block>
bool Contiguous(const Block& b) {
  return b.outerStride() == b.rows() || b.cols() == 1;
}
template <typename Block>
auto Flat(Block&& b) {
  using Pointee = std::remove_pointer_t<decltype(b.data())>;
  using Array = Eigen::Array<std::remove_const_t<Pointee>, Eigen::Dynamic, 1>;
  return Eigen::Map<std::conditional_t<std::is_const_v<Pointee>, const Array, Array>>(b.data(), b.size());
}

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
  SmallProduct<Scalar>(r, d_prev, pre);
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
  SmallProduct<Scalar, true>(wz, z, u);
  h = ((h_prev.array().colwise() * keep.array()) + (u.array().colwise() * rate.array())).matrix();
  // h and d are whole columns (contiguous): one flat tanh, not one per column with scalar tails.
  if (Contiguous(h) && Contiguous(d))
    Flat(d) = Flat(h).tanh();
  else
    d = h.array().tanh().matrix();
}

// In place on `x` (output_units x columns, logits on entry): the softmax of every DOF's block,
// column by column. Unless `log_x` is null, it receives log x (same shape). No allocation.
template <typename Scalar>
void SoftmaxPerDof(const NetworkLayout& layout, MatrixT<Scalar>& x, MatrixT<Scalar>* log_x) {
  const int dofs = layout.spec().num_dofs();
  for (int j = 0; j < x.cols(); ++j)
    for (int dof = 0; dof < dofs; ++dof) {
      auto c = x.col(j).segment(layout.output_offset(dof), layout.output_units(dof));
      c.array() -= c.maxCoeff();
    }
  if (log_x != nullptr) *log_x = x;
  // One vectorised exp over the whole matrix: a DOF's block (10 units) is shorter than a packet.
  x.array() = x.array().exp();
  for (int j = 0; j < x.cols(); ++j)
    for (int dof = 0; dof < dofs; ++dof) {
      const int off = layout.output_offset(dof), n = layout.output_units(dof);
      auto c = x.col(j).segment(off, n);
      const Scalar sum = c.sum();
      c /= sum;
      if (log_x != nullptr) log_x->col(j).segment(off, n).array() -= std::log(sum);
    }
}

}  // namespace dyad::pvrnn::internal
