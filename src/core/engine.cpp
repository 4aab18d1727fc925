// synthesize(): dispatch to the reference or the OpenCL engine.
#include "amytiss/engine.hpp"

#include "opencl_engine.hpp"

namespace amytiss {

Policy synthesize(const Abstraction& abstraction, const SynthesisOptions& options,
                  SynthesisReport* report) {
  if (options.compute.device == DeviceKind::Reference) {
    if (report) report->log.push_back("device: reference (serial, double precision)");
    return synthesize_reference(abstraction, options.progress, report);
  }
  return detail::synthesize_opencl(abstraction, options, report);
}

}  // namespace amytiss
