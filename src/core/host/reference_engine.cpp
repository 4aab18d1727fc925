// The reference engine is its Bellman step (host/reference_step.cpp) run by the one backward
// driver; it computes every transition when it needs it, so there is nothing to construct.
#include "host/reference_engine.hpp"

#include "host/backward_driver.hpp"
#include "host/reference_step.hpp"

namespace amytiss::detail {

Policy run_reference(const Abstraction& abstraction, const ProgressCallback& progress, SynthesisReport& report) {
  report.transitions = "on_the_fly (the reference engine computes each transition when it needs it)";
  StepReporter reporter(abstraction, progress, report);
  reporter.set_device("reference");
  reporter.reached(Phase::Setup);
  ReferenceStep step(abstraction);
  return run_backward(abstraction, step, reporter);
}

}  // namespace amytiss::detail
