#include "dyad/pvrnn/softmax_encoding.hpp"

#include <cmath>

namespace dyad::pvrnn {

Eigen::MatrixXd EncodePositions(const OutputEncoding& enc, const Eigen::MatrixXd& positions) {
  Eigen::MatrixXd codes(enc.TotalUnits(), positions.cols());
  int off = 0;
  for (int dof = 0; dof < static_cast<int>(enc.dofs.size()); ++dof) {
    const int n = enc.UnitsFor(dof);
    const double lo = enc.dofs[dof].min, span = enc.dofs[dof].max - lo;
    const double inv_s2 = 1.0 / (enc.sigma * enc.sigma);
    for (int j = 0; j < positions.cols(); ++j) {
      const double v = (positions(dof, j) - lo) / span;
      double sum = 0;
      for (int i = 0; i < n; ++i) {
        const double r = static_cast<double>(i) / (n - 1);
        codes(off + i, j) = std::exp(-(r - v) * (r - v) * inv_s2);
        sum += codes(off + i, j);
      }
      codes.col(j).segment(off, n) /= sum;
    }
    off += n;
  }
  return codes;
}

Eigen::MatrixXd DecodePositions(const OutputEncoding& enc, const Eigen::MatrixXd& codes) {
  Eigen::MatrixXd pos(enc.dofs.size(), codes.cols());
  int off = 0;
  for (int dof = 0; dof < static_cast<int>(enc.dofs.size()); ++dof) {
    const int n = enc.UnitsFor(dof);
    const double lo = enc.dofs[dof].min, span = enc.dofs[dof].max - lo;
    for (int j = 0; j < codes.cols(); ++j) {
      double v = 0;
      for (int i = 0; i < n; ++i) v += codes(off + i, j) * static_cast<double>(i) / (n - 1);
      pos(dof, j) = lo + span * v;
    }
    off += n;
  }
  return pos;
}

template <typename Scalar>
void EncodePosition(const OutputEncoding& enc, const double* position, Scalar* code) {
  int off = 0;
  const double inv_s2 = 1.0 / (enc.sigma * enc.sigma);
  for (int dof = 0; dof < static_cast<int>(enc.dofs.size()); ++dof) {
    const int n = enc.UnitsFor(dof);
    const double lo = enc.dofs[dof].min, span = enc.dofs[dof].max - lo;
    const double v = (position[dof] - lo) / span;
    double sum = 0;
    for (int i = 0; i < n; ++i) {
      const double r = static_cast<double>(i) / (n - 1);
      sum += std::exp(-(r - v) * (r - v) * inv_s2);
    }
    for (int i = 0; i < n; ++i) {
      const double r = static_cast<double>(i) / (n - 1);
      code[off + i] = static_cast<Scalar>(std::exp(-(r - v) * (r - v) * inv_s2) / sum);
    }
    off += n;
  }
}

template <typename Scalar>
void DecodePosition(const OutputEncoding& enc, const Scalar* code, double* position) {
  int off = 0;
  for (int dof = 0; dof < static_cast<int>(enc.dofs.size()); ++dof) {
    const int n = enc.UnitsFor(dof);
    const double lo = enc.dofs[dof].min, span = enc.dofs[dof].max - lo;
    double v = 0;
    for (int i = 0; i < n; ++i) v += static_cast<double>(code[off + i]) * static_cast<double>(i) / (n - 1);
    position[dof] = lo + span * v;
    off += n;
  }
}

template void EncodePosition(const OutputEncoding&, const double*, float*);
template void EncodePosition(const OutputEncoding&, const double*, double*);
template void DecodePosition(const OutputEncoding&, const float*, double*);
template void DecodePosition(const OutputEncoding&, const double*, double*);

}  // namespace dyad::pvrnn
