#include "common/host_memory.hpp"

#ifdef __GLIBC__
#include <malloc.h>
#endif

#include <sys/mman.h>

#include <algorithm>
#include <cstdlib>
#include <new>

namespace amytiss::detail {

namespace {
constexpr std::size_t kHugePage = std::size_t(2) << 20;
}  // namespace

HostBlock::HostBlock(std::size_t bytes) {
  const std::size_t rounded = (std::max<std::size_t>(bytes, 1) + kHugePage - 1) / kHugePage * kHugePage;
  data_.reset(std::aligned_alloc(kHugePage, rounded));
  if (!data_) throw std::bad_alloc();
  // Advice only: where the kernel has no transparent huge pages the block works as it is.
  madvise(data_.get(), rounded, MADV_HUGEPAGE);
}

void HostBlock::Free::operator()(void* data) const { std::free(data); }

double* HostDoubles::reserve(std::size_t count) {
  if (count > capacity_) {
    block_.reset();  // the old block goes before the new one is taken
    block_ = std::make_unique<HostBlock>(count * sizeof(double));
    capacity_ = count;
  }
  return data();
}

void release_free_heap() {
#ifdef __GLIBC__
  malloc_trim(0);
#endif
}

}  // namespace amytiss::detail
