#pragma once
// Host memory for large tensors: the buffers of a CPU OpenCL device (pocl; with
// CL_MEM_USE_HOST_PTR the block is the device memory itself) and the host's interval sweeps.
// Blocks are aligned to 2 MiB and offered to the kernel for transparent huge pages, so a stage
// that streams a large tensor takes one page fault and one TLB entry per 2 MiB instead of per
// 4 KiB (on virtual machines a page fault can cost 15-20 us).
#include <cstddef>
#include <memory>

namespace amytiss::detail {

/// Gives the heap's free pages back to the system (glibc keeps freed small blocks resident):
/// between phases, so that one phase's temporaries do not add to the next phase's peak.
void release_free_heap();

class HostBlock {
 public:
  /// At least `bytes` (rounded up to whole 2 MiB), untouched; throws std::bad_alloc.
  explicit HostBlock(std::size_t bytes);
  void* data() const { return data_.get(); }

 private:
  struct Free {
    void operator()(void* data) const;
  };
  std::unique_ptr<void, Free> data_;
};

/// Doubles in a HostBlock that grows on demand. Never zero-filled: the first writer of an entry
/// touches its page, so parallel writers fault their pages in in parallel.
class HostDoubles {
 public:
  /// Room for `count` doubles; the contents are lost when it grows.
  double* reserve(std::size_t count);
  double* data() const { return block_ ? static_cast<double*>(block_->data()) : nullptr; }

 private:
  std::unique_ptr<HostBlock> block_;
  std::size_t capacity_ = 0;
};

}  // namespace amytiss::detail
