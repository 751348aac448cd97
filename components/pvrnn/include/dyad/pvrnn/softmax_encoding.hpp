// dyad/pvrnn/softmax_encoding.hpp: positions <-> per-DOF softmax codes (NRL's encoding).
//
// For one DOF with range [min, max] and n units, reference points r_i = i/(n-1) on [0,1];
// a position x maps to v = (x-min)/(max-min) and p_i ~ exp(-(r_i - v)^2 / sigma^2), normalised.
// Decoding is x = min + (max-min) * sum_i p_i r_i. Codes of all DOFs are stacked (DOF 0 first).
#pragma once

#include <Eigen/Core>

#include "dyad/pvrnn/model_spec.hpp"

namespace dyad::pvrnn {

// positions: num_dofs x N (one column per sample). Returns TotalUnits() x N.
Eigen::MatrixXd EncodePositions(const OutputEncoding& enc, const Eigen::MatrixXd& positions);
// codes: TotalUnits() x N. Returns num_dofs x N positions.
Eigen::MatrixXd DecodePositions(const OutputEncoding& enc, const Eigen::MatrixXd& codes);

// One sample, no allocation (the online path): `position` has num_dofs entries, `code`
// TotalUnits() entries. Same numbers as the matrix versions.
template <typename Scalar>
void EncodePosition(const OutputEncoding& enc, const double* position, Scalar* code);
template <typename Scalar>
void DecodePosition(const OutputEncoding& enc, const Scalar* code, double* position);

}  // namespace dyad::pvrnn
