#pragma once
// Writing HDF5 files: the file is built in memory (HDF5's core driver, no backing store) and its
// bytes are handed to the caller, who writes them to disk. HDF5 itself then never meets a full
// disk or an I/O error: HDF5 1.10 cannot close a file whose close-time flush failed (the
// identifier stays half-destroyed and the library crashes at exit), and errors of the caller's own
// writes carry the system's reason.
//
//   Hdf5MemoryFile file;
//   Hdf5Writer writer(file.id());
//   writer.string_attribute("format", "amytiss-policy");
//   writer.dataset("/values", shape, H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, values.data());
//   const Hdf5Image image = file.close_to_image();   // image.data(), image.size() bytes
//
// Every failure throws PolicyFileError("cannot write <what>: <HDF5's reason>").
#include <hdf5.h>

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <memory>
#include <string>
#include <vector>

#include "io/hdf5_handle.hpp"

namespace amytiss::detail {

/// The bytes of a closed HDF5 file.
class Hdf5Image {
 public:
  Hdf5Image(void* memory, std::size_t size) : memory_(memory, &std::free), size_(size) {}
  const char* data() const { return static_cast<const char*>(memory_.get()); }
  std::size_t size() const { return size_; }

 private:
  std::unique_ptr<void, decltype(&std::free)> memory_;
  std::size_t size_;
};

class Hdf5MemoryFile {
 public:
  Hdf5MemoryFile();
  ~Hdf5MemoryFile();
  Hdf5MemoryFile(const Hdf5MemoryFile&) = delete;
  Hdf5MemoryFile& operator=(const Hdf5MemoryFile&) = delete;

  hid_t id() const { return file_.get(); }
  /// Flushes and closes the file (every object opened in it must be closed) and returns its bytes.
  Hdf5Image close_to_image();

  /// Where the core driver's memory goes: the buffer it releases at close is kept here.
  struct Memory {
    void* released_at_close = nullptr;
  };

 private:
  std::unique_ptr<Memory> memory_;
  Hdf5Handle file_;
};

/// Typed writes into the root group of an open file. Stored types are little-endian and fixed;
/// memory types are the native types of the data given.
class Hdf5Writer {
 public:
  explicit Hdf5Writer(hid_t file) : file_(file) {}

  void string_attribute(const std::string& name, const std::string& value) const;
  /// Stored as uint32 (the format's attributes are small counts).
  void unsigned_attribute(const std::string& name, std::uint64_t value) const;
  void string_dataset(const std::string& name, const std::string& value) const;
  void group(const std::string& name) const;
  /// What a non-empty dataset passes through besides the Fletcher-32 checksum, which every HDF5
  /// reader verifies on every read: Compressed adds HDF5's shuffle and deflate filters (every HDF5
  /// build with zlib reads them: h5py, MATLAB, h5dump).
  enum class Filters { ChecksumOnly, Compressed };
  /// A dataset of `shape`; non-empty ones are chunked: whole trailing dimensions, at most
  /// kChunkBytes per chunk.
  void dataset(const std::string& name, const std::vector<hsize_t>& shape, hid_t file_type, hid_t memory_type,
               const void* data, Filters filters = Filters::ChecksumOnly) const;

  /// HDF5's default chunk cache size: a reader's chunk buffers are then reused from one chunk to
  /// the next instead of being mapped afresh (larger chunks made loading bmw_parking's file a
  /// quarter slower; BENCHMARKS.md, "Policy file sizes").
  static constexpr std::uint64_t kChunkBytes = 1u << 20;
  /// zlib level of Filters::Compressed: 1 compresses policy arrays almost as well as 4 at a
  /// fraction of the time (BENCHMARKS.md, "Policy file sizes").
  static constexpr unsigned kDeflateLevel = 1;

 private:
  void check(herr_t status, const std::string& what) const;
  Hdf5Handle checked(hid_t id, Hdf5Handle::Closer closer, const std::string& what) const;
  Hdf5Handle string_type(const std::string& what) const;

  hid_t file_;
};

}  // namespace amytiss::detail
