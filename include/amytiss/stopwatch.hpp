#pragma once
// The one clock of the package's timings (phase reports, progress, the CLI's wall times).
#include <chrono>

namespace amytiss {

using SteadyClock = std::chrono::steady_clock;

/// Seconds from `start` to now on the steady clock.
inline double seconds_since(SteadyClock::time_point start) {
  return std::chrono::duration<double>(SteadyClock::now() - start).count();
}

}  // namespace amytiss
