// dyad/pvrnn/nrl_import.hpp: read a model trained by NRL/VCBot into a dyad Model.
//
// Inputs: the model folder (L<l>_{w,b,au,al}_p.d, o<k>_{w,b}_p.d, optional epoch.d and
// training.txt), its properties_*.d (d, z, t, w, dsoft, sigma, activejoints, epochs, alpha,
// beta1, beta2) and the data set it was trained on (for the number of primitives and steps).
// NRL stores one matrix per line, comma-separated, column-major. Layer weight files hold, in
// order: W_dh, W_zh, W_mu_p, W_ls_p, W_mu_q, W_ls_q, then W_below (if not the lowest layer)
// and W_above (if not the top). Bias files: b_h, b_mu_p, b_ls_p, b_mu_q, b_ls_q. A files: one
// line per primitive and step (primitive-major). The Cartesian robot's joints range -50..50.
//
// Errors name the file (and line) and the mismatch, e.g. "L0_w_p.d:3: expected 160 values
// (4 x 40: W_mu_p), found 150". Only NRL's plain PV-RNN (network=pvrnn, or no network key:
// NRL before its Beta network) is imported; network=pvrnnbeta is refused, and a Beta model's
// weight files (no W_below) fail with an error that says so.
#pragma once

#include <string>

#include "dyad/pvrnn/dataset.hpp"
#include "dyad/pvrnn/model.hpp"

namespace dyad::pvrnn {

struct NrlImportOptions {
  std::string model_dir;        // e.g. .../vcbot/model/MacawBot
  std::string properties_file;  // e.g. .../vcbot/config/properties_MacawBot.d
  std::string dataset_dir;      // e.g. .../vcbot/dataset/Macaw
};

StatusOr<Model> ImportNrlModel(const NrlImportOptions& options);

// key=value lines (NRL's properties and dataset.d); '#' starts a comment.
StatusOr<std::vector<std::pair<std::string, std::string>>> ReadKeyValueFile(const std::string& path);

}  // namespace dyad::pvrnn
