// The synthesis plan: `auto` chooses the engine by the planned work (the serial engine where an
// OpenCL kernel build would dominate) and says why; explicit requests are honoured; --dry-run
// describes every plan.
#include <gtest/gtest.h>

#include <algorithm>
#include <string>
#include <vector>

#include "amytiss/engine.hpp"
#include "plan.hpp"
#include "test_support.hpp"

namespace amytiss {
namespace {

using test_support::from_yaml;

// A 2-d walk: 64 cells, 9 inputs, a few hundred thousand multiply-adds in all.
const char* kTiny =
    "name: tiny_walk\n"
    "states: {lb: [-2, -2], ub: [2, 2], eta: [0.5, 0.5]}\n"
    "inputs: {lb: [-1, -1], ub: [1, 1], eta: [1, 1]}\n"
    "dynamics: [\"x0 + 0.5*u0\", \"x1 + 0.5*u1\"]\n"
    "noise: {covariance: [0.04, 0.04], truncation: cutting_probability, cutting_probability: 1.0e-4}\n"
    "spec: {type: safety, horizon: 5, safe: {lb: [-1.5, -1.5], ub: [1.5, 1.5]}}\n";

// The same walk on a 160 x 160 grid with 121 inputs: billions of multiply-adds.
const char* kLarge =
    "name: large_walk\n"
    "states: {lb: [-2, -2], ub: [2, 2], eta: [0.025, 0.025]}\n"
    "inputs: {lb: [-1, -1], ub: [1, 1], eta: [0.2, 0.2]}\n"
    "dynamics: [\"x0 + 0.5*u0\", \"x1 + 0.5*u1\"]\n"
    "noise: {covariance: [0.04, 0.04], truncation: cutting_probability, cutting_probability: 1.0e-4}\n"
    "spec: {type: safety, horizon: 10, safe: {lb: [-1.5, -1.5], ub: [1.5, 1.5]}}\n";

bool has_note(const std::vector<EngineNote>& notes, const std::string& fragment) {
  return std::any_of(notes.begin(), notes.end(),
                     [&](const EngineNote& note) { return note.text.find(fragment) != std::string::npos; });
}

SynthesisOptions options_for(DeviceKind device) {
  SynthesisOptions options;
  options.compute.device = device;
  return options;
}

TEST(Plan, AutoRunsATinyProblemOnTheSerialEngineAndNamesThePlannedWork) {
  const Abstraction a = from_yaml(kTiny);
  SynthesisReport report;
  const Policy policy = synthesize(a, options_for(DeviceKind::Auto), &report);
  EXPECT_EQ(report.device, "reference");
  EXPECT_EQ(policy.computed_by, "reference");
  EXPECT_TRUE(has_note(report.notes, "device auto: the serial reference engine (planned work "));
  EXPECT_TRUE(has_note(report.notes, "multiply-adds per step"));
  EXPECT_EQ(policy.values, synthesize_reference(a, {}, nullptr).values);
}

TEST(Plan, AutoPlansAnOpenClDeviceWhereTheWorkPaysForTheBuild) {
  const Abstraction a = from_yaml(kLarge);
  const detail::SynthesisPlan plan = detail::plan_synthesis(a, options_for(DeviceKind::Auto));
  EXPECT_EQ(plan.engine, detail::EngineKind::OneDevice);
  EXPECT_TRUE(plan.may_fall_back);
  EXPECT_TRUE(has_note(plan.notes, "device auto: an OpenCL device (planned work "));
  EXPECT_GT(plan.multiply_adds_per_step, detail::planned_multiply_adds_per_step(from_yaml(kTiny)));
}

TEST(Plan, ExplicitRequestsAreNeverReplacedByTheSerialEngine) {
  const Abstraction a = from_yaml(kTiny);
  const detail::SynthesisPlan cpu = detail::plan_synthesis(a, options_for(DeviceKind::Cpu));
  EXPECT_EQ(cpu.engine, detail::EngineKind::OneDevice);
  EXPECT_FALSE(cpu.may_fall_back);
  SynthesisOptions named = options_for(DeviceKind::Auto);
  named.compute.platform = "0";
  EXPECT_EQ(detail::plan_synthesis(a, named).engine, detail::EngineKind::OneDevice);
  EXPECT_EQ(detail::plan_synthesis(a, options_for(DeviceKind::Reference)).engine, detail::EngineKind::Reference);
}

TEST(Plan, DryRunDescribesEveryEngine) {
  const Abstraction tiny = from_yaml(kTiny);
  const std::vector<std::string> serial = describe_synthesis(tiny, options_for(DeviceKind::Auto));
  ASSERT_FALSE(serial.empty());
  EXPECT_EQ(serial.front(), "engine: reference (serial, double precision)");
  SynthesisOptions dense = options_for(DeviceKind::Cpu);
  dense.compute.sweep = SweepChoice::Dense;
  const std::vector<std::string> device = describe_synthesis(tiny, dense);
  EXPECT_EQ(device.front(), "engine: OpenCL, one device");
  EXPECT_TRUE(std::any_of(device.begin(), device.end(),
                          [](const std::string& line) { return line.rfind("transitions: stored", 0) == 0; }));
}

}  // namespace
}  // namespace amytiss
