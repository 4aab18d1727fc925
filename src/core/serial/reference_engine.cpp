// The reference engine is its Bellman step (serial/reference_step.cpp) run by the one backward
// driver; it computes every transition when it needs it, so there is nothing to construct.
#include "serial/reference_engine.hpp"

#include "solve/backward_driver.hpp"
#include "serial/reference_step.hpp"
#include "serial/point_iteration.hpp"

namespace amytiss::detail {

Policy run_reference(const Abstraction& abstraction, const ProgressCallback& progress, SynthesisReport& report) {
  report.transitions = "on_the_fly (the reference engine computes each transition when it needs it)";
  StepReporter reporter(abstraction, progress, report);
  reporter.set_device("reference");
  reporter.reached(Phase::Setup);
  ReferenceStep step(abstraction);
  return run_abstraction_backward(abstraction, step, reporter);
}

}  // namespace amytiss::detail
