#pragma once
// The serial reference engine (the paper's Algorithms 1 + 3 in double precision): the oracle the
// OpenCL engines are tested against, and the engine `auto` chooses for tiny problems.
#include "amytiss/abstraction.hpp"
#include "amytiss/policy.hpp"
#include "amytiss/synthesis_types.hpp"

namespace amytiss::detail {

/// Runs the reference engine; report gets the device "reference", the phases and the progress.
Policy run_reference(const Abstraction& abstraction, const ProgressCallback& progress, SynthesisReport& report);

}  // namespace amytiss::detail
