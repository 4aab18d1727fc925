// The roofline arithmetic of --profile: intensity, roof, the bound that sets it, the fraction.
#include <gtest/gtest.h>

#include "amytiss/roofline.hpp"

namespace amytiss {
namespace {

// Each figure is one or two floating-point operations from the inputs.
constexpr double kRelativeTolerance = 1e-12;
constexpr double kPeak = 80e9;        // multiply-adds per second
constexpr double kBandwidth = 40e9;   // bytes per second

TEST(Roofline, LowIntensityIsBoundByMemory) {
  // 1e9 multiply-adds over 8e9 bytes: 0.125 MAC/B, roof 0.125 x 40e9 = 5e9 < 80e9; achieved 4e9.
  const RooflinePoint point = roofline_point(kPeak, kBandwidth, 1e9, 8e9, 0.25);
  EXPECT_NEAR(point.intensity, 0.125, kRelativeTolerance * 0.125);
  EXPECT_NEAR(point.roof, 5e9, kRelativeTolerance * 5e9);
  EXPECT_EQ(point.bound, RoofKind::Memory);
  EXPECT_NEAR(point.achieved, 4e9, kRelativeTolerance * 4e9);
  EXPECT_NEAR(point.fraction_of_roof, 0.8, kRelativeTolerance);
  EXPECT_EQ(to_string(point.bound), "memory");
}

TEST(Roofline, HighIntensityIsBoundByThePeak) {
  // 8e9 multiply-adds over 1e9 bytes: 8 MAC/B, 8 x 40e9 = 320e9 > 80e9: the peak; achieved 40e9.
  const RooflinePoint point = roofline_point(kPeak, kBandwidth, 8e9, 1e9, 0.2);
  EXPECT_NEAR(point.intensity, 8.0, kRelativeTolerance * 8.0);
  EXPECT_NEAR(point.roof, kPeak, kRelativeTolerance * kPeak);
  EXPECT_EQ(point.bound, RoofKind::Compute);
  EXPECT_NEAR(point.fraction_of_roof, 0.5, kRelativeTolerance);
  EXPECT_EQ(to_string(point.bound), "compute");
}

TEST(Roofline, TheRidgePointIsBoundByThePeak) {
  // At peak / bandwidth = 2 MAC/B both roofs meet: the compute roof is named.
  const RooflinePoint point = roofline_point(kPeak, kBandwidth, 2e9, 1e9, 1.0);
  EXPECT_EQ(point.bound, RoofKind::Compute);
  EXPECT_NEAR(point.roof, kPeak, kRelativeTolerance * kPeak);
}

}  // namespace
}  // namespace amytiss
