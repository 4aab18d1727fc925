#pragma once
// Work split over the host's cores: contiguous parts of an index range, one thread each.
#include <cstddef>
#include <functional>

namespace amytiss::detail {

/// Runs body(part, first, last) over [0, count) split into min(threads, count) contiguous parts
/// (part 0, 1, ...) on as many threads (the calling thread takes part 0); rethrows the first
/// exception of a part.
void parallel_for(std::size_t count, unsigned threads,
                  const std::function<void(unsigned part, std::size_t first, std::size_t last)>& body);

/// Worker threads for the host's interval MDP work: the hardware's concurrency (at least 1).
unsigned host_threads();

}  // namespace amytiss::detail
