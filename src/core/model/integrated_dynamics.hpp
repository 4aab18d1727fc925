#pragma once
// A vector field stepped by the integrator (models/integrator.h) into a discrete map.
#include <memory>

#include "amytiss/config.hpp"
#include "amytiss/model.hpp"

namespace amytiss::detail {

/// x(k+1) = the integrator's step of length tau (seconds) applied to `field`.
std::unique_ptr<Dynamics> make_integrated_dynamics(std::unique_ptr<VectorField> field,
                                                   const IntegratorConfig& integrator, double tau);

}  // namespace amytiss::detail
