// Internal: one time step of the stacked network for a block of columns. Shared by the
// posterior pass (training, error regression) and the prior generator so both run the same code.
#pragma once

#include <Eigen/Core>

namespace dyad::pvrnn::internal {

template <typename Scalar>
using Mat = Eigen::Matrix<Scalar, Eigen::Dynamic, Eigen::Dynamic>;
template <typename Scalar>
using Vec = Eigen::Matrix<Scalar, Eigen::Dynamic, 1>;
template <typename Scalar>
using Out = Eigen::Ref<Mat<Scalar>>;
template <typename Scalar>
using In = Eigen::Ref<const Mat<Scalar>>;

// Where z comes from in this step.
enum class Source { kPosterior, kPrior };

// pre = R d_prev + b; fills mu/logsigma of prior and posterior (posterior adds A), z and the new
// h, d. `a_mu`/`a_ls` are read only for Source::kPosterior. No allocation.
template <typename Scalar, typename RMat, typename BVec, typename WzMat>
inline void StepForward(const RMat& r, const BVec& rbias, const WzMat& wz, const Vec<Scalar>& rate,
                        const Vec<Scalar>& keep, int total_d, int total_z, Source source,
                        In<Scalar> d_prev, In<Scalar> h_prev, In<Scalar> a_mu, In<Scalar> a_ls,
                        In<Scalar> eps, Out<Scalar> pre, Out<Scalar> mu_p, Out<Scalar> ls_p,
                        Out<Scalar> sig_p, Out<Scalar> mu_q, Out<Scalar> ls_q, Out<Scalar> sig_q,
                        Out<Scalar> z, Out<Scalar> h, Out<Scalar> d) {
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
  u.noalias() += wz.lazyProduct(z);
  h = ((h_prev.array().colwise() * keep.array()) + (u.array().colwise() * rate.array())).matrix();
  d = h.array().tanh().matrix();
}

}  // namespace dyad::pvrnn::internal
