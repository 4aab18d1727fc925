#pragma once
// HDF5 basics shared by the reader and the writer: an owning identifier, silencing HDF5's own
// error printing, and the reason HDF5 gives for the last failure.
#include <hdf5.h>

#include <string>

namespace amytiss::detail {

/// Owns one HDF5 identifier and closes it with the matching close function (H5Dclose, H5Tclose,
/// ...). close() reports the close status; the destructor closes what is still open and ignores
/// the status (it runs when something else already failed).
class Hdf5Handle {
 public:
  using Closer = herr_t (*)(hid_t);
  Hdf5Handle(hid_t id, Closer closer) : id_(id), closer_(closer) {}
  ~Hdf5Handle() { close(); }
  Hdf5Handle(const Hdf5Handle&) = delete;
  Hdf5Handle& operator=(const Hdf5Handle&) = delete;
  Hdf5Handle(Hdf5Handle&& other) noexcept : id_(other.id_), closer_(other.closer_) { other.id_ = -1; }

  hid_t get() const { return id_; }
  bool valid() const { return id_ >= 0; }
  /// Closes now; false when the close function failed.
  bool close() {
    if (id_ < 0) return true;
    const hid_t id = id_;
    id_ = -1;
    return closer_(id) >= 0;
  }

 private:
  hid_t id_;
  Closer closer_;
};

/// HDF5 prints its error stack to stderr by default; amytiss reports through exceptions only.
/// H5Eset_auto is per thread in thread-safe builds, so it is silenced around every operation.
class SilenceHdf5Errors {
 public:
  SilenceHdf5Errors();
  ~SilenceHdf5Errors();
  SilenceHdf5Errors(const SilenceHdf5Errors&) = delete;
  SilenceHdf5Errors& operator=(const SilenceHdf5Errors&) = delete;

 private:
  H5E_auto2_t previous_function_ = nullptr;
  void* previous_data_ = nullptr;
};

/// The description of the innermost entry of this thread's HDF5 error stack (the lowest-level
/// reason of the last failure, e.g. "memory allocation failed"), or "" when the stack is empty.
std::string hdf5_error_reason();

}  // namespace amytiss::detail
