#include "dyad/pvrnn/prior_generator.hpp"

#include <gtest/gtest.h>

#include "dyad/pvrnn/softmax_encoding.hpp"

namespace dyad::pvrnn {
namespace {

Model Small() {
  ModelSpec spec = ModelSpec::MacawBot();
  spec.layers[0].d = 8;
  spec.layers[1].d = 4;
  return Model::Initialize(spec, 6, 3, 5);
}

TEST(PriorGenerator, WithoutNoiseIsReproducible) {
  const Model m = Small();
  const Eigen::MatrixXd a = GeneratePrimitive(m, 1, 20, GenerateOptions{});
  const Eigen::MatrixXd b = GeneratePrimitive(m, 1, 20, GenerateOptions{});
  EXPECT_EQ(a, b);
}

TEST(PriorGenerator, NoiseFollowsTheSeed) {
  const Model m = Small();
  GenerateOptions o;
  o.noise = true;
  o.seed = 3;
  const Eigen::MatrixXd a = GeneratePrimitive(m, 0, 20, o);
  EXPECT_EQ(a, GeneratePrimitive(m, 0, 20, o));
  o.seed = 4;
  EXPECT_NE(a, GeneratePrimitive(m, 0, 20, o));
}

TEST(PriorGenerator, PrimitiveIsSelectedByItsAdaptiveVariables) {
  const Model m = Small();
  EXPECT_NE(GeneratePrimitive(m, 0, 10, GenerateOptions{}), GeneratePrimitive(m, 2, 10, GenerateOptions{}));
}

// Stepping keeps the state: two runs of 5 steps equal one run of 10 from the same start.
TEST(PriorGenerator, StepwiseGenerationKeepsItsState) {
  const Model m = Small();
  const int tz = m.adaptive.total_z();
  PriorGenerator<double> g1(m.weights, 1), g2(m.weights, 1);
  const Eigen::MatrixXd eps = Eigen::MatrixXd::Zero(tz, 1);
  for (int t = 0; t < 10; ++t) g1.Step(nullptr, nullptr, eps);
  for (int t = 0; t < 5; ++t) g2.Step(nullptr, nullptr, eps);
  const NetworkState<double> mid = g2.state();
  PriorGenerator<double> g3(m.weights, 1);
  g3.Reset(mid);
  for (int t = 0; t < 5; ++t) g3.Step(nullptr, nullptr, eps);
  EXPECT_TRUE(g3.state().h.isApprox(g1.state().h, 1e-14));
  EXPECT_TRUE(g3.outputs().isApprox(g1.outputs(), 1e-14));
}

}  // namespace
}  // namespace dyad::pvrnn
