#include "io/hdf5_writer.hpp"

#include <algorithm>
#include <cstring>

#include "amytiss/errors.hpp"

namespace amytiss::detail {
namespace {

// The core driver grows its buffer in steps of this many bytes.
constexpr std::size_t kMemoryIncrement = 1u << 20;
// /dev/null is not a folder, so nothing exists under it.
constexpr const char* kNoSuchFile = "/dev/null/amytiss-policy-in-memory.h5";

// File image callbacks: the core driver allocates through these, and the buffer it frees when the
// file closes is kept (Hdf5MemoryFile::Memory) instead of released, so the image is not copied.
void* image_malloc(std::size_t size, H5FD_file_image_op_t, void*) { return std::malloc(size); }
void* image_memcpy(void* destination, const void* source, std::size_t size, H5FD_file_image_op_t, void*) {
  return std::memcpy(destination, source, size);
}
void* image_realloc(void* memory, std::size_t size, H5FD_file_image_op_t, void*) {
  return std::realloc(memory, size);
}
herr_t image_free(void* memory, H5FD_file_image_op_t operation, void* user_data) {
  if (operation == H5FD_FILE_IMAGE_OP_FILE_CLOSE)
    static_cast<Hdf5MemoryFile::Memory*>(user_data)->released_at_close = memory;
  else
    std::free(memory);
  return 0;
}
// The property list copies the user data; every copy is the same Memory object.
void* share_user_data(void* user_data) { return user_data; }
herr_t keep_user_data(void*) { return 0; }

[[noreturn]] void cannot_write(const std::string& what) {
  const std::string reason = hdf5_error_reason();
  throw PolicyFileError("cannot write " + what + (reason.empty() ? "" : ": " + reason));
}

hid_t create_in_memory(Hdf5MemoryFile::Memory& memory) {
  Hdf5Handle access(H5Pcreate(H5P_FILE_ACCESS), H5Pclose);
  if (!access.valid() || H5Pset_fapl_core(access.get(), kMemoryIncrement, false) < 0) cannot_write("the file");
  H5FD_file_image_callbacks_t callbacks{image_malloc,    image_memcpy,   image_realloc, image_free,
                                        share_user_data, keep_user_data, &memory};
  if (H5Pset_file_image_callbacks(access.get(), &callbacks) < 0) cannot_write("the file");
  // Without a backing store nothing is created on disk, but HDF5 first tries to open an existing
  // file of that name (and the core driver would read it all): the name is one no file can have.
  const hid_t file = H5Fcreate(kNoSuchFile, H5F_ACC_TRUNC, H5P_DEFAULT, access.get());
  if (file < 0) cannot_write("the file");
  return file;
}

// Chunk extents for an array of `shape`: whole trailing dimensions while they fit kChunkBytes.
std::vector<hsize_t> chunk_shape(const std::vector<hsize_t>& shape, std::size_t element_bytes) {
  std::vector<hsize_t> chunk(shape.size(), 1);
  std::uint64_t bytes = element_bytes;
  for (std::size_t dim = shape.size(); dim-- > 0;) {
    const std::uint64_t fit = std::max<std::uint64_t>(1, Hdf5Writer::kChunkBytes / bytes);
    chunk[dim] = hsize_t(std::min<std::uint64_t>(shape[dim], fit));
    bytes *= chunk[dim];
    if (chunk[dim] < shape[dim]) break;
  }
  return chunk;
}

}  // namespace

Hdf5MemoryFile::Hdf5MemoryFile()
    : memory_(std::make_unique<Memory>()), file_(create_in_memory(*memory_), H5Fclose) {}

Hdf5MemoryFile::~Hdf5MemoryFile() {
  file_.close();
  std::free(memory_->released_at_close);
}

Hdf5Image Hdf5MemoryFile::close_to_image() {
  if (H5Fflush(file_.get(), H5F_SCOPE_GLOBAL) < 0) cannot_write("the file (flush)");
  const ssize_t size = H5Fget_file_image(file_.get(), nullptr, 0);
  if (size <= 0) cannot_write("the file (image size)");
  if (!file_.close()) cannot_write("the file (close)");
  if (!memory_->released_at_close)
    throw PolicyFileError("cannot write the file: objects in it were still open when it was closed");
  // The image is the first `size` bytes (the end of the file's allocated address space) of the
  // buffer; the buffer beyond is the driver's growth reserve.
  Hdf5Image image(memory_->released_at_close, std::size_t(size));
  memory_->released_at_close = nullptr;
  return image;
}

void Hdf5Writer::check(herr_t status, const std::string& what) const {
  if (status < 0) cannot_write(what);
}

Hdf5Handle Hdf5Writer::checked(hid_t id, Hdf5Handle::Closer closer, const std::string& what) const {
  if (id < 0) cannot_write(what);
  return Hdf5Handle(id, closer);
}

Hdf5Handle Hdf5Writer::string_type(const std::string& what) const {
  Hdf5Handle type = checked(H5Tcopy(H5T_C_S1), H5Tclose, what);
  check(H5Tset_size(type.get(), H5T_VARIABLE), what);
  check(H5Tset_cset(type.get(), H5T_CSET_UTF8), what);
  return type;
}

void Hdf5Writer::string_attribute(const std::string& name, const std::string& value) const {
  const std::string what = "attribute " + name;
  Hdf5Handle type = string_type(what);
  Hdf5Handle space = checked(H5Screate(H5S_SCALAR), H5Sclose, what);
  Hdf5Handle attribute =
      checked(H5Acreate2(file_, name.c_str(), type.get(), space.get(), H5P_DEFAULT, H5P_DEFAULT), H5Aclose, what);
  const char* text = value.c_str();
  check(H5Awrite(attribute.get(), type.get(), &text), what);
  check(attribute.close() ? 0 : -1, what);
}

void Hdf5Writer::unsigned_attribute(const std::string& name, std::uint64_t value) const {
  const std::string what = "attribute " + name;
  Hdf5Handle space = checked(H5Screate(H5S_SCALAR), H5Sclose, what);
  Hdf5Handle attribute =
      checked(H5Acreate2(file_, name.c_str(), H5T_STD_U32LE, space.get(), H5P_DEFAULT, H5P_DEFAULT), H5Aclose, what);
  check(H5Awrite(attribute.get(), H5T_NATIVE_UINT64, &value), what);
  check(attribute.close() ? 0 : -1, what);
}

void Hdf5Writer::string_dataset(const std::string& name, const std::string& value) const {
  Hdf5Handle type = string_type(name);
  Hdf5Handle space = checked(H5Screate(H5S_SCALAR), H5Sclose, name);
  Hdf5Handle dataset = checked(
      H5Dcreate2(file_, name.c_str(), type.get(), space.get(), H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), H5Dclose, name);
  const char* text = value.c_str();
  check(H5Dwrite(dataset.get(), type.get(), H5S_ALL, H5S_ALL, H5P_DEFAULT, &text), name);
  check(dataset.close() ? 0 : -1, name);
}

void Hdf5Writer::group(const std::string& name) const {
  Hdf5Handle group = checked(H5Gcreate2(file_, name.c_str(), H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), H5Gclose, name);
  check(group.close() ? 0 : -1, name);
}

void Hdf5Writer::dataset(const std::string& name, const std::vector<hsize_t>& shape, hid_t file_type,
                         hid_t memory_type, const void* data, Filters filters) const {
  Hdf5Handle space =
      checked(H5Screate_simple(int(shape.size()), shape.empty() ? nullptr : shape.data(), nullptr), H5Sclose, name);
  hsize_t elements = 1;
  for (hsize_t extent : shape) elements *= extent;
  Hdf5Handle properties = checked(H5Pcreate(H5P_DATASET_CREATE), H5Pclose, name);
  if (elements > 0) {
    const std::vector<hsize_t> chunk = chunk_shape(shape, H5Tget_size(file_type));
    check(H5Pset_chunk(properties.get(), int(chunk.size()), chunk.data()), name);
    if (filters == Filters::Compressed) {
      if (H5Zfilter_avail(H5Z_FILTER_DEFLATE) <= 0)
        throw PolicyFileError("cannot write " + name + ": this HDF5 library has no deflate (zlib) filter");
      // Shuffle groups the bytes of equal significance, so the slowly varying high bytes of
      // probabilities compress well; the checksum comes last and covers the compressed bytes.
      check(H5Pset_shuffle(properties.get()), name);
      check(H5Pset_deflate(properties.get(), kDeflateLevel), name);
    }
    check(H5Pset_fletcher32(properties.get()), name);
  }
  Hdf5Handle dataset = checked(
      H5Dcreate2(file_, name.c_str(), file_type, space.get(), H5P_DEFAULT, properties.get(), H5P_DEFAULT), H5Dclose,
      name);
  // A zero-sized dataset (the input grid of an autonomous system) has nothing to write, and
  // H5Dwrite refuses a null buffer.
  if (elements > 0) check(H5Dwrite(dataset.get(), memory_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, data), name);
  // Closing a chunked dataset writes its cached chunks: a failure here is a failed write.
  check(dataset.close() ? 0 : -1, name);
}

}  // namespace amytiss::detail
