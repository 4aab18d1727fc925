#include "common/parallel_for.hpp"

#include <algorithm>
#include <exception>
#include <mutex>
#include <thread>
#include <vector>

namespace amytiss::detail {

void parallel_for(std::size_t count, unsigned threads,
                  const std::function<void(unsigned part, std::size_t first, std::size_t last)>& body) {
  threads = unsigned(std::max<std::size_t>(1, std::min<std::size_t>(threads, count)));
  std::exception_ptr failure;
  std::mutex failure_mutex;
  auto part = [&](unsigned t) {
    try {
      body(t, count * t / threads, count * (t + 1) / threads);
    } catch (...) {
      std::lock_guard<std::mutex> lock(failure_mutex);
      if (!failure) failure = std::current_exception();
    }
  };
  std::vector<std::thread> workers;
  for (unsigned t = 1; t < threads; ++t) workers.emplace_back(part, t);
  part(0);
  for (std::thread& worker : workers) worker.join();
  if (failure) std::rethrow_exception(failure);
}

unsigned host_threads() { return std::max(1u, std::thread::hardware_concurrency()); }

}  // namespace amytiss::detail
