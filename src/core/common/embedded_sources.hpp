#pragma once
// OpenCL C sources embedded in the library at build time (cmake/embed.cmake): src/core/opencl/kernels/*.cl
// and src/core/model/models/*.h, by file name.
#include <string>

namespace amytiss::detail {

/// Text of the embedded file with this base name ("engine.cl", "bmw320i.h"); throws
/// std::logic_error when no such file was embedded.
const char* embedded_source(const std::string& name);

}  // namespace amytiss::detail
