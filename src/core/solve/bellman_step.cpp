#include "solve/bellman_step.hpp"

#include <stdexcept>

namespace amytiss::detail {

void BellmanStep::evaluate(const double*, double*, const std::uint32_t*) {
  throw std::logic_error("this Bellman step cannot evaluate a fixed controller: only the host's steps can");
}

}  // namespace amytiss::detail
