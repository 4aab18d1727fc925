#include "amytiss/run_id.hpp"

#include <cstdint>
#include <random>

#include "amytiss/format.hpp"

namespace amytiss {

std::string new_run_id() {
  std::random_device device;
  const std::uint64_t id = (std::uint64_t(device()) << 32) ^ std::uint64_t(device());
  return hex16(id);
}

}  // namespace amytiss
