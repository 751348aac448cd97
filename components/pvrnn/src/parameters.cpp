#include "dyad/pvrnn/parameters.hpp"

#include <cmath>

namespace dyad::pvrnn {

template <typename Scalar>
Weights<Scalar>::Weights(const NetworkLayout& layout)
    : layout_(std::make_shared<const NetworkLayout>(layout)),
      flat_(VectorT<Scalar>::Zero(layout.num_weights())) {}

template <typename Scalar>
Weights<Scalar> Weights<Scalar>::Random(const NetworkLayout& layout, std::mt19937_64& rng) {
  Weights w(layout);
  for (const auto& g : layout.groups()) {
    // fan_in: columns of a weight block; biases use their own length (as NRL does).
    const int fan_in = g.cols > 1 ? g.cols : g.rows;
    const double bound = 1.0 / std::sqrt(static_cast<double>(fan_in));
    std::uniform_real_distribution<double> u(-bound, bound);
    auto v = w.Group(g);
    for (int c = 0; c < g.cols; ++c)
      for (int r = 0; r < g.rows; ++r) v(r, c) = static_cast<Scalar>(u(rng));
  }
  return w;
}

template <typename Scalar>
MatrixMap<Scalar> Weights<Scalar>::Piece(pvrnn::Piece p) {
  return MatrixMap<Scalar>(flat_.data() + layout_->piece_offset(p), layout_->piece_rows(p),
                           layout_->piece_cols(p));
}

template <typename Scalar>
ConstMatrixMap<Scalar> Weights<Scalar>::Piece(pvrnn::Piece p) const {
  return ConstMatrixMap<Scalar>(flat_.data() + layout_->piece_offset(p), layout_->piece_rows(p),
                                layout_->piece_cols(p));
}

template <typename Scalar>
StridedMap<Scalar> Weights<Scalar>::Group(const ParameterGroup& g) {
  const int rows = layout_->piece_rows(g.piece);
  return StridedMap<Scalar>(flat_.data() + layout_->piece_offset(g.piece) + g.col * rows + g.row,
                            g.rows, g.cols, Eigen::OuterStride<>(rows));
}

template <typename Scalar>
ConstStridedMap<Scalar> Weights<Scalar>::Group(const ParameterGroup& g) const {
  const int rows = layout_->piece_rows(g.piece);
  return ConstStridedMap<Scalar>(flat_.data() + layout_->piece_offset(g.piece) + g.col * rows + g.row,
                                 g.rows, g.cols, Eigen::OuterStride<>(rows));
}

template <typename Scalar>
void Weights<Scalar>::ApplyMask() {
  auto r = R();
  for (int i = 0; i < r.size(); ++i)
    if (!layout_->r_mask()[i]) r.data()[i] = 0;
  auto wz = Wz();
  for (int i = 0; i < wz.size(); ++i)
    if (!layout_->wz_mask()[i]) wz.data()[i] = 0;
}

template <typename Scalar>
AdaptiveVariables<Scalar>::AdaptiveVariables(int total_z, int steps, int sequences)
    : total_z_(total_z), steps_(steps), sequences_(sequences),
      flat_(VectorT<Scalar>::Zero(2 * total_z * steps * sequences)) {}

template class Weights<float>;
template class Weights<double>;
template class AdaptiveVariables<float>;
template class AdaptiveVariables<double>;

}  // namespace dyad::pvrnn
