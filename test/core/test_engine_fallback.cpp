// Only `auto` may run elsewhere than asked: a device it chose that fails is retried once on the CPU
// device with a warning note; an explicit kind, platform or device is honoured or fails
// (docs/engine.md).
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "amytiss/errors.hpp"
#include "execute.hpp"

namespace amytiss {
namespace {

const std::string kGpuLabel = "NVIDIA CUDA / NVIDIA H100";
const std::string kCpuLabel = "Portable Computing Language / pthread";

// An attempt that fails on every device but the CPU one and records what it was asked for.
struct ScriptedEngine {
  std::vector<DeviceKind> requested;
  bool cpu_fails = false;

  Policy operator()(const SynthesisOptions& options, SynthesisReport* report) {
    requested.push_back(options.compute.device);
    const bool on_cpu = options.compute.device == DeviceKind::Cpu;
    report->device = on_cpu ? kCpuLabel : kGpuLabel;
    report->notes.push_back({NoteSeverity::Info, NoteKind::DeviceChoice, "attempt on " + report->device});
    if (!on_cpu || cpu_fails) throw DeviceError("clEnqueueNDRangeKernel failed: CL_OUT_OF_RESOURCES");
    Policy policy;
    policy.computed_by = report->device;
    return policy;
  }
};

detail::DeviceLabel cpu_device_is(const std::string& label) {
  return [label](const ComputeConfig&) { return label; };
}

SynthesisOptions options_for(DeviceKind device) {
  SynthesisOptions options;
  options.compute.device = device;
  return options;
}

TEST(EngineFallback, AutoChoiceThatFailsIsRetriedOnTheCpuDeviceWithAWarning) {
  ScriptedEngine engine;
  SynthesisReport report;
  const Policy policy = detail::synthesize_with_cpu_fallback(
      options_for(DeviceKind::Auto), &report, std::ref(engine), cpu_device_is(kCpuLabel));

  EXPECT_EQ(policy.computed_by, kCpuLabel);
  ASSERT_EQ(engine.requested.size(), 2u);
  EXPECT_EQ(engine.requested[1], DeviceKind::Cpu);
  EXPECT_EQ(report.device, kCpuLabel);
  bool warned = false;
  for (const auto& note : report.notes)
    warned = warned || (note.severity == NoteSeverity::Warning && note.kind == NoteKind::DeviceFallback &&
                        note.text.rfind(kGpuLabel + " failed (", 0) == 0 &&
                        note.text.find("CL_OUT_OF_RESOURCES") != std::string::npos &&
                        note.text.find("falling back to the CPU device " + kCpuLabel) != std::string::npos);
  EXPECT_TRUE(warned) << "no fallback warning in the report log";
}

TEST(EngineFallback, ExplicitGpuOrCpuRequestIsNotRetried) {
  for (DeviceKind kind : {DeviceKind::Gpu, DeviceKind::Cpu}) {
    ScriptedEngine engine;
    engine.cpu_fails = true;
    EXPECT_THROW(detail::synthesize_with_cpu_fallback(options_for(kind), nullptr, std::ref(engine),
                                                      cpu_device_is(kCpuLabel)),
                 DeviceError);
    EXPECT_EQ(engine.requested.size(), 1u);
  }
}

TEST(EngineFallback, AutoWithAPlatformOrDeviceSelectionIsNotRetried) {
  for (const char* key : {"platform", "device_name"}) {
    SynthesisOptions options = options_for(DeviceKind::Auto);
    (std::string(key) == "platform" ? options.compute.platform : options.compute.device_name) = "nvidia";
    ScriptedEngine engine;
    EXPECT_THROW(detail::synthesize_with_cpu_fallback(options, nullptr, std::ref(engine), cpu_device_is(kCpuLabel)),
                 DeviceError);
    EXPECT_EQ(engine.requested.size(), 1u) << key;
  }
}

TEST(EngineFallback, NoRetryWhenTheFailingDeviceIsTheCpuDeviceOrThereIsNone) {
  ScriptedEngine engine;
  EXPECT_THROW(detail::synthesize_with_cpu_fallback(options_for(DeviceKind::Auto), nullptr,
                                                    std::ref(engine), cpu_device_is(kGpuLabel)),
               DeviceError);
  EXPECT_EQ(engine.requested.size(), 1u);

  ScriptedEngine no_cpu;
  EXPECT_THROW(detail::synthesize_with_cpu_fallback(options_for(DeviceKind::Auto), nullptr,
                                                    std::ref(no_cpu), cpu_device_is("")),
               DeviceError);
  EXPECT_EQ(no_cpu.requested.size(), 1u);
}

TEST(EngineFallback, CpuFailureAfterFallbackPropagates) {
  ScriptedEngine engine;
  engine.cpu_fails = true;
  EXPECT_THROW(detail::synthesize_with_cpu_fallback(options_for(DeviceKind::Auto), nullptr,
                                                    std::ref(engine), cpu_device_is(kCpuLabel)),
               DeviceError);
  EXPECT_EQ(engine.requested.size(), 2u);
}

TEST(EngineFallback, CancellationIsNotADeviceFailure) {
  int attempts = 0;
  const detail::EngineAttempt cancelled = [&attempts](const SynthesisOptions&, SynthesisReport*) -> Policy {
    ++attempts;
    throw Cancelled();
  };
  EXPECT_THROW(detail::synthesize_with_cpu_fallback(options_for(DeviceKind::Auto), nullptr, cancelled,
                                                    cpu_device_is(kCpuLabel)),
               Cancelled);
  EXPECT_EQ(attempts, 1);
}

TEST(EngineFallback, SelectedDeviceLabelNamesTheCpuDeviceOfThisMachine) {
  ComputeConfig compute;
  compute.device = DeviceKind::Cpu;
  // Every machine that runs the tests has pocl's CPU device (CI included).
  EXPECT_NE(detail::selected_device_label(compute), "");
  compute.platform = "no platform has this name";
  EXPECT_EQ(detail::selected_device_label(compute), "");
}

}  // namespace
}  // namespace amytiss
