// The roofline arithmetic of --profile: intensities, roofs, the bound that sets it, the fraction.
#include <gtest/gtest.h>

#include "amytiss/roofline.hpp"

namespace amytiss {
namespace {

// Each figure is one or two floating-point operations from the inputs.
constexpr double kRelativeTolerance = 1e-12;
constexpr RooflineDevice kDevice{80e9, 40e9, 0};  // multiply-adds, memory bytes per second

TEST(Roofline, LowIntensityIsBoundByMemory) {
  // 1e9 multiply-adds over 8e9 bytes: 0.125 MAC/B, roof 0.125 x 40e9 = 5e9 < 80e9; achieved 4e9.
  const RooflinePoint point = roofline_point(kDevice, {1e9, 8e9, 0, 0.25});
  EXPECT_NEAR(point.memory_intensity, 0.125, kRelativeTolerance * 0.125);
  EXPECT_NEAR(point.operand_intensity, 0.125, kRelativeTolerance * 0.125);
  EXPECT_NEAR(point.roof, 5e9, kRelativeTolerance * 5e9);
  EXPECT_EQ(point.bound, RoofKind::Memory);
  EXPECT_NEAR(point.achieved, 4e9, kRelativeTolerance * 4e9);
  EXPECT_NEAR(point.fraction_of_roof, 0.8, kRelativeTolerance);
  EXPECT_EQ(to_string(point.bound), "memory");
}

TEST(Roofline, HighIntensityIsBoundByThePeak) {
  // 8e9 multiply-adds over 1e9 bytes: 8 MAC/B, 8 x 40e9 = 320e9 > 80e9: the peak; achieved 40e9.
  const RooflinePoint point = roofline_point(kDevice, {8e9, 1e9, 0, 0.2});
  EXPECT_NEAR(point.memory_intensity, 8.0, kRelativeTolerance * 8.0);
  EXPECT_NEAR(point.roof, kDevice.peak, kRelativeTolerance * kDevice.peak);
  EXPECT_EQ(point.bound, RoofKind::Compute);
  EXPECT_NEAR(point.fraction_of_roof, 0.5, kRelativeTolerance);
  EXPECT_EQ(to_string(point.bound), "compute");
}

TEST(Roofline, TheRidgePointIsBoundByThePeak) {
  // At peak / bandwidth = 2 MAC/B both roofs meet: the compute roof is named.
  const RooflinePoint point = roofline_point(kDevice, {2e9, 1e9, 0, 1.0});
  EXPECT_EQ(point.bound, RoofKind::Compute);
  EXPECT_NEAR(point.roof, kDevice.peak, kRelativeTolerance * kDevice.peak);
}

TEST(Roofline, OperandsFromCacheBoundAStageThatMovesLittleMemory) {
  // A stage of 4e9 multiply-adds that loads 16e9 operand bytes (0.25 MAC/B) but moves only 1e9
  // bytes of tensors (4 MAC/B: memory roof 160e9 > peak). With a cache bandwidth of 200e9 B/s its
  // operands allow 0.25 x 200e9 = 50e9 multiply-adds per second: the cache roof; achieved 40e9.
  const RooflineDevice device{80e9, 40e9, 200e9};
  const RooflinePoint point = roofline_point(device, {4e9, 16e9, 1e9, 0.1});
  EXPECT_NEAR(point.memory_intensity, 4.0, kRelativeTolerance * 4.0);
  EXPECT_NEAR(point.operand_intensity, 0.25, kRelativeTolerance * 0.25);
  EXPECT_EQ(point.bound, RoofKind::Cache);
  EXPECT_NEAR(point.roof, 50e9, kRelativeTolerance * 50e9);
  EXPECT_NEAR(point.fraction_of_roof, 0.8, kRelativeTolerance);
  EXPECT_EQ(to_string(point.bound), "cache");
  // Without the memory bytes there is no cache roof: the operand bytes stand for memory traffic.
  const RooflinePoint uncounted = roofline_point(device, {4e9, 16e9, 0, 0.1});
  EXPECT_EQ(uncounted.bound, RoofKind::Memory);
  EXPECT_NEAR(uncounted.roof, 10e9, kRelativeTolerance * 10e9);
  // A slow memory bounds it below the cache roof: 4 MAC/B x 10e9 B/s = 40e9 < 50e9.
  const RooflinePoint slow_memory = roofline_point({80e9, 10e9, 200e9}, {4e9, 16e9, 1e9, 0.1});
  EXPECT_EQ(slow_memory.bound, RoofKind::Memory);
  EXPECT_NEAR(slow_memory.roof, 40e9, kRelativeTolerance * 40e9);
}

}  // namespace
}  // namespace amytiss
