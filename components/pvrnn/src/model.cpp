#include "dyad/pvrnn/model.hpp"

#include <cmath>
#include <random>

namespace dyad::pvrnn {

Model Model::Initialize(const ModelSpec& spec, int steps, int sequences, uint64_t seed) {
  Model m;
  m.spec = spec;
  NetworkLayout layout(spec);
  std::mt19937_64 rng(seed);
  m.weights = Weights<double>::Random(layout, rng);
  m.adaptive = AdaptiveVariables<double>(layout.total_z(), steps, sequences);
  for (int k = 0; k < layout.num_layers(); ++k) {
    const int z = spec.layers[k].z, off = layout.z_offset(k);
    std::uniform_real_distribution<double> u(-1.0 / std::sqrt(z), 1.0 / std::sqrt(z));
    for (auto view : {m.adaptive.mu(), m.adaptive.log_sigma()})
      for (int c = 0; c < view.cols(); ++c)
        for (int r = 0; r < z; ++r) view(off + r, c) = u(rng);
  }
  m.provenance.seed = seed;
  return m;
}

}  // namespace dyad::pvrnn
