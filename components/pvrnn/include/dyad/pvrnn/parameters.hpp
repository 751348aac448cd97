// dyad/pvrnn/parameters.hpp: the trainable numbers of a PV-RNN, as flat vectors with views.
//
// Contract
// - `Weights<Scalar>` holds every weight and bias in one contiguous vector (layout from
//   NetworkLayout), so an optimiser updates it with one loop and a gradient has the same type.
//   `R()`, `RBias()`, `Wz()`, `Wx()`, `Bx()` are the stacked pieces; `Group(g)` a named block.
// - `AdaptiveVariables<Scalar>` holds A for `sequences` columns and `steps` steps:
//   `mu()` and `log_sigma()` are total_z x (steps*sequences) with column t*sequences + s, so the
//   A of one step for all sequences is one contiguous block (`mu().middleCols(t * sequences, sequences)`).
// - Both are regular values (copyable); `Cast<T>()` converts the scalar type.
#pragma once

#include <Eigen/Core>
#include <memory>
#include <random>

#include "dyad/pvrnn/network_layout.hpp"

namespace dyad::pvrnn {

template <typename Scalar>
using MatrixT = Eigen::Matrix<Scalar, Eigen::Dynamic, Eigen::Dynamic>;
template <typename Scalar>
using VectorT = Eigen::Matrix<Scalar, Eigen::Dynamic, 1>;
template <typename Scalar>
using MatrixMap = Eigen::Map<MatrixT<Scalar>>;
template <typename Scalar>
using ConstMatrixMap = Eigen::Map<const MatrixT<Scalar>>;
template <typename Scalar>
using StridedMap = Eigen::Map<MatrixT<Scalar>, 0, Eigen::OuterStride<>>;
template <typename Scalar>
using ConstStridedMap = Eigen::Map<const MatrixT<Scalar>, 0, Eigen::OuterStride<>>;

template <typename Scalar>
class Weights {
 public:
  Weights() = default;
  // All zero.
  explicit Weights(const NetworkLayout& layout);
  // NRL-style Kaiming-uniform initialisation: U(-1/sqrt(fan_in), +1/sqrt(fan_in)).
  static Weights Random(const NetworkLayout& layout, std::mt19937_64& rng);

  const NetworkLayout& layout() const { return *layout_; }
  VectorT<Scalar>& flat() { return flat_; }
  const VectorT<Scalar>& flat() const { return flat_; }

  MatrixMap<Scalar> Piece(pvrnn::Piece p);
  ConstMatrixMap<Scalar> Piece(pvrnn::Piece p) const;
  MatrixMap<Scalar> R() { return Piece(Piece::kR); }
  ConstMatrixMap<Scalar> R() const { return Piece(Piece::kR); }
  MatrixMap<Scalar> RBias() { return Piece(Piece::kRBias); }
  ConstMatrixMap<Scalar> RBias() const { return Piece(Piece::kRBias); }
  MatrixMap<Scalar> Wz() { return Piece(Piece::kWz); }
  ConstMatrixMap<Scalar> Wz() const { return Piece(Piece::kWz); }
  MatrixMap<Scalar> Wx() { return Piece(Piece::kWx); }
  ConstMatrixMap<Scalar> Wx() const { return Piece(Piece::kWx); }
  MatrixMap<Scalar> Bx() { return Piece(Piece::kBx); }
  ConstMatrixMap<Scalar> Bx() const { return Piece(Piece::kBx); }

  StridedMap<Scalar> Group(const ParameterGroup& g);
  ConstStridedMap<Scalar> Group(const ParameterGroup& g) const;

  // Zeroes the structural zeros of R and Wz (used on gradients).
  void ApplyMask();

  template <typename T>
  Weights<T> Cast() const {
    Weights<T> out(*layout_);
    out.flat() = flat_.template cast<T>();
    return out;
  }

 private:
  std::shared_ptr<const NetworkLayout> layout_;
  VectorT<Scalar> flat_;
  template <typename T> friend class Weights;
};

template <typename Scalar>
class AdaptiveVariables {
 public:
  AdaptiveVariables() = default;
  AdaptiveVariables(int total_z, int steps, int sequences);  // all zero

  int total_z() const { return total_z_; }
  int steps() const { return steps_; }
  int sequences() const { return sequences_; }
  VectorT<Scalar>& flat() { return flat_; }
  const VectorT<Scalar>& flat() const { return flat_; }

  MatrixMap<Scalar> mu() { return MatrixMap<Scalar>(flat_.data(), total_z_, cols()); }
  ConstMatrixMap<Scalar> mu() const { return ConstMatrixMap<Scalar>(flat_.data(), total_z_, cols()); }
  MatrixMap<Scalar> log_sigma() { return MatrixMap<Scalar>(flat_.data() + half(), total_z_, cols()); }
  ConstMatrixMap<Scalar> log_sigma() const {
    return ConstMatrixMap<Scalar>(flat_.data() + half(), total_z_, cols());
  }
  int cols() const { return steps_ * sequences_; }
  int Column(int step, int sequence) const { return step * sequences_ + sequence; }

  template <typename T>
  AdaptiveVariables<T> Cast() const {
    AdaptiveVariables<T> out(total_z_, steps_, sequences_);
    out.flat() = flat_.template cast<T>();
    return out;
  }

 private:
  int half() const { return total_z_ * cols(); }
  int total_z_ = 0, steps_ = 0, sequences_ = 0;
  VectorT<Scalar> flat_;
};

}  // namespace dyad::pvrnn
