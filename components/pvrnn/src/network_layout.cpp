#include "dyad/pvrnn/network_layout.hpp"

namespace dyad::pvrnn {

NetworkLayout::NetworkLayout(const ModelSpec& spec) : spec_(spec) {
  const int K = static_cast<int>(spec.layers.size());
  for (int k = 0; k < K; ++k) {
    d_offset_.push_back(total_d_);
    z_offset_.push_back(total_z_);
    total_d_ += spec.layers[k].d;
    total_z_ += spec.layers[k].z;
    for (int i = 0; i < spec.layers[k].d; ++i) rate_.push_back(1.0 / spec.layers[k].tau);
  }
  for (int i = 0; i < spec.num_dofs(); ++i) {
    x_offset_.push_back(output_units_);
    x_units_.push_back(spec.output.UnitsFor(i));
    output_units_ += x_units_.back();
  }
  int off = 0;
  for (int p = 0; p < 5; ++p) {
    piece_offset_[p] = off;
    off += piece_rows(static_cast<Piece>(p)) * piece_cols(static_cast<Piece>(p));
  }
  num_weights_ = off;

  const int rmp = row_mu_p(), rlp = row_ls_p(), rmq = row_mu_q(), rlq = row_ls_q();
  for (int k = 0; k < K; ++k) {
    const int d = spec.layers[k].d, z = spec.layers[k].z, dof = d_offset_[k], zof = z_offset_[k];
    const std::string L = "L" + std::to_string(k) + ".";
    groups_.push_back({L + "W_dh", Piece::kR, dof, dof, d, d});
    groups_.push_back({L + "W_zh", Piece::kWz, dof, zof, d, z});
    groups_.push_back({L + "W_mu_p", Piece::kR, rmp + zof, dof, z, d});
    groups_.push_back({L + "W_ls_p", Piece::kR, rlp + zof, dof, z, d});
    groups_.push_back({L + "W_mu_q", Piece::kR, rmq + zof, dof, z, d});
    groups_.push_back({L + "W_ls_q", Piece::kR, rlq + zof, dof, z, d});
    if (k > 0)
      groups_.push_back({L + "W_below", Piece::kR, dof, d_offset_[k - 1], d, spec.layers[k - 1].d});
    if (k + 1 < K)
      groups_.push_back({L + "W_above", Piece::kR, dof, d_offset_[k + 1], d, spec.layers[k + 1].d});
    groups_.push_back({L + "b_h", Piece::kRBias, dof, 0, d, 1});
    groups_.push_back({L + "b_mu_p", Piece::kRBias, rmp + zof, 0, z, 1});
    groups_.push_back({L + "b_ls_p", Piece::kRBias, rlp + zof, 0, z, 1});
    groups_.push_back({L + "b_mu_q", Piece::kRBias, rmq + zof, 0, z, 1});
    groups_.push_back({L + "b_ls_q", Piece::kRBias, rlq + zof, 0, z, 1});
  }
  for (int i = 0; i < spec.num_dofs(); ++i) {
    groups_.push_back({"out.W_x" + std::to_string(i), Piece::kWx, x_offset_[i], 0, x_units_[i], d0()});
    groups_.push_back({"out.b_x" + std::to_string(i), Piece::kBx, x_offset_[i], 0, x_units_[i], 1});
  }
  r_mask_.assign(static_cast<size_t>(recurrent_rows()) * total_d_, 0);
  wz_mask_.assign(static_cast<size_t>(total_d_) * total_z_, 0);
  for (const auto& g : groups_) {
    std::vector<unsigned char>* mask = g.piece == Piece::kR ? &r_mask_ : g.piece == Piece::kWz ? &wz_mask_ : nullptr;
    if (mask == nullptr) continue;
    const int rows = piece_rows(g.piece);
    for (int c = 0; c < g.cols; ++c)
      for (int r = 0; r < g.rows; ++r) (*mask)[static_cast<size_t>(g.col + c) * rows + g.row + r] = 1;
  }
}

int NetworkLayout::piece_rows(Piece p) const {
  switch (p) {
    case Piece::kR:
    case Piece::kRBias: return recurrent_rows();
    case Piece::kWz: return total_d_;
    case Piece::kWx:
    case Piece::kBx: return output_units_;
  }
  return 0;
}

int NetworkLayout::piece_cols(Piece p) const {
  switch (p) {
    case Piece::kR: return total_d_;
    case Piece::kWz: return total_z_;
    case Piece::kWx: return d0();
    case Piece::kRBias:
    case Piece::kBx: return 1;
  }
  return 0;
}

const ParameterGroup* NetworkLayout::FindGroup(const std::string& name) const {
  for (const auto& g : groups_)
    if (g.name == name) return &g;
  return nullptr;
}

}  // namespace dyad::pvrnn
