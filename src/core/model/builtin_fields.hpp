#pragma once
// The built-in models' vector fields: the C functions of model/models/*.h, on the host and as
// OpenCL C text.
#include <memory>

#include "amytiss/model.hpp"

namespace amytiss::detail {

/// The vector field of built-in model `info` (one of builtin_models()); nullptr when it has no
/// C function.
std::unique_ptr<VectorField> make_builtin_field(const BuiltinModelInfo& info);

}  // namespace amytiss::detail
