#include "dyad/pvrnn/softmax_encoding.hpp"

#include <gtest/gtest.h>

namespace dyad::pvrnn {
namespace {

TEST(SoftmaxEncoding, MacawRangeHasTenUnitsPerDof) {
  const ModelSpec spec = ModelSpec::MacawBot();
  EXPECT_EQ(spec.output.UnitsFor(0), 10);
  EXPECT_EQ(spec.output.TotalUnits(), 20);
}

TEST(SoftmaxEncoding, CodesAreNormalisedAndPeakAtThePosition) {
  const ModelSpec spec = ModelSpec::MacawBot();
  Eigen::MatrixXd pos(2, 3);
  pos << -50, 0, 50, 50, 0, -50;
  const Eigen::MatrixXd codes = EncodePositions(spec.output, pos);
  for (int j = 0; j < 3; ++j) {
    EXPECT_NEAR(codes.col(j).head(10).sum(), 1.0, 1e-12);
    EXPECT_NEAR(codes.col(j).tail(10).sum(), 1.0, 1e-12);
  }
  Eigen::Index peak;
  codes.col(0).head(10).maxCoeff(&peak);
  EXPECT_EQ(peak, 0);
  codes.col(2).head(10).maxCoeff(&peak);
  EXPECT_EQ(peak, 9);
}

TEST(SoftmaxEncoding, DecodingInvertsEncodingInsideTheRange) {
  const ModelSpec spec = ModelSpec::MacawBot();
  Eigen::MatrixXd pos(2, 5);
  pos << -30, -10, 0, 12.5, 30, 25, -5, 0, 7, -30;
  const Eigen::MatrixXd back = DecodePositions(spec.output, EncodePositions(spec.output, pos));
  // The bump is cut off at the ends of [0, 1], so decoding is pulled towards the centre as a
  // position nears the edges (a property of NRL's code): exact at the centre, ~1 unit at +-30.
  EXPECT_NEAR(back(0, 2), 0.0, 1e-9);
  EXPECT_LT((back - pos).cwiseAbs().maxCoeff(), 1.5);
}

}  // namespace
}  // namespace dyad::pvrnn
