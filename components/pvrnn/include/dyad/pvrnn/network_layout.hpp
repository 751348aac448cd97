// dyad/pvrnn/network_layout.hpp: where every weight of a PV-RNN lives, computed from a ModelSpec.
//
// The engine stacks all layers so that one step is two small matrix products for the whole
// network and all sequences at once (sequences are columns):
// - the state D = [d_0; d_1; ...] (total_d rows) and likewise H;
// - the recurrent matrix R (recurrent_rows() x total_d) maps D(t-1) to the pre-activations
//   [U_h | mu_p | logsigma_p | mu_q | logsigma_q]: rows 0..total_d-1 hold, per layer k, the
//   blocks W_dh (from d_k), W_below (from d_{k-1}) and W_above (from d_{k+1}); the four z
//   blocks (total_z rows each) hold the prior/posterior weights of layer k (from d_k only).
//   Structural zeros (no connection) are masked and stay zero.
// - Wz (total_d x total_z) is block diagonal: W_zh of each layer.
// - Wx (total output units x d_0) and bx: the softmax output of every DOF, stacked.
// Every named parameter group (e.g. "L0.W_dh") is a strided view into one of these pieces.
#pragma once

#include <string>
#include <vector>

#include "dyad/pvrnn/model_spec.hpp"

namespace dyad::pvrnn {

enum class Piece { kR = 0, kRBias = 1, kWz = 2, kWx = 3, kBx = 4 };

struct ParameterGroup {
  std::string name;  // "L<k>.<W_dh|W_below|W_above|W_zh|b_h|W_mu_p|...>" or "out.W_x<i>", "out.b_x<i>"
  Piece piece;
  int row = 0, col = 0, rows = 0, cols = 0;  // block inside the piece
};

class NetworkLayout {
 public:
  explicit NetworkLayout(const ModelSpec& spec);

  const ModelSpec& spec() const { return spec_; }
  int num_layers() const { return static_cast<int>(spec_.layers.size()); }
  int total_d() const { return total_d_; }
  int total_z() const { return total_z_; }
  int output_units() const { return output_units_; }
  int d0() const { return spec_.layers[0].d; }
  int d_offset(int k) const { return d_offset_[k]; }
  int z_offset(int k) const { return z_offset_[k]; }
  int output_offset(int dof) const { return x_offset_[dof]; }
  int output_units(int dof) const { return x_units_[dof]; }

  // Rows of R: [U_h: total_d | mu_p | logsigma_p | mu_q | logsigma_q: total_z each].
  int recurrent_rows() const { return total_d_ + 4 * total_z_; }
  int row_mu_p() const { return total_d_; }
  int row_ls_p() const { return total_d_ + total_z_; }
  int row_mu_q() const { return total_d_ + 2 * total_z_; }
  int row_ls_q() const { return total_d_ + 3 * total_z_; }

  // Sizes and offsets of the pieces in the flat weight vector.
  int piece_rows(Piece p) const;
  int piece_cols(Piece p) const;
  int piece_offset(Piece p) const { return piece_offset_[static_cast<int>(p)]; }
  int num_weights() const { return num_weights_; }

  // All named groups, in a stable order (the model file and NRL import rely on the names).
  const std::vector<ParameterGroup>& groups() const { return groups_; }
  const ParameterGroup* FindGroup(const std::string& name) const;

  // 1 where R / Wz hold a real connection, 0 at structural zeros (column-major, piece shape).
  const std::vector<unsigned char>& r_mask() const { return r_mask_; }
  const std::vector<unsigned char>& wz_mask() const { return wz_mask_; }

  // Per-row leak rate 1/tau of the stacked state (total_d entries).
  const std::vector<double>& rate() const { return rate_; }

 private:
  ModelSpec spec_;
  int total_d_ = 0, total_z_ = 0, output_units_ = 0, num_weights_ = 0;
  std::vector<int> d_offset_, z_offset_, x_offset_, x_units_;
  int piece_offset_[5] = {0, 0, 0, 0, 0};
  std::vector<ParameterGroup> groups_;
  std::vector<unsigned char> r_mask_, wz_mask_;
  std::vector<double> rate_;
};

}  // namespace dyad::pvrnn
