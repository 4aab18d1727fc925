// The built-in models (model/models/*.h): their C functions, dimensions and OpenCL C text.
#include "model/builtin_fields.hpp"

#include <math.h>

#include <string>

#include "common/embedded_sources.hpp"

namespace amytiss {
namespace builtin {
// The model sources are plain C shared with the OpenCL kernels; they use the global math functions.
#include "model/models/model_function.h"
#include "model/models/commonroad_vehicle2.h"
#include "model/models/bmw320i.h"
#include "model/models/bmw320i_ks.h"
#include "model/models/vehicle3d.h"
}  // namespace builtin

namespace detail {
namespace {

using RateFunction = void (*)(const double*, const double*, const double*, double*);

/// What this file knows of a built-in model beyond BuiltinModelInfo: its C function, the model
/// sources its OpenCL text needs (in order), and which components each rate reads when stated.
struct BuiltinSource {
  const char* name;
  RateFunction rate;
  std::vector<const char*> headers;
  std::optional<std::vector<VariableUse>> dependencies;
};

const std::vector<BuiltinSource>& builtin_sources() {
  static const std::vector<BuiltinSource> sources = {
      {"bmw320i", &builtin::amytiss_rate_bmw320i, {"commonroad_vehicle2.h", "bmw320i.h"}, std::nullopt},
      {"bmw320i_ks",
       &builtin::amytiss_rate_bmw320i_ks,
       {"commonroad_vehicle2.h", "bmw320i_ks.h"},
       std::vector<VariableUse>{{{3, 4}, {}, {}}, {{3, 4}, {}, {}}, {{2}, {0}, {}}, {{3}, {1}, {}}, {{2, 3}, {}, {}}}},
      {"vehicle3d",
       &builtin::amytiss_rate_vehicle3d,
       {"vehicle3d.h"},
       std::vector<VariableUse>{{{2}, {0, 1}, {}}, {{2}, {0, 1}, {}}, {{}, {0, 1}, {}}}},
  };
  return sources;
}

class BuiltinField : public VectorField {
 public:
  BuiltinField(const BuiltinModelInfo& info, const BuiltinSource& source) : info_(info), source_(source) {}

  std::size_t state_dims() const override { return info_.state_dims; }
  std::size_t input_dims() const override { return info_.input_dims; }
  std::size_t disturbance_dims() const override { return info_.disturbance_dims; }

  void rate(const double* x, const double* u, const double* w, double* rate) const override {
    source_.rate(x, u, w, rate);
  }

  std::string opencl_source() const override {
    std::string source = embedded_source("model_function.h");
    for (const char* header : source_.headers) source += embedded_source(header);
    return source +
           "\nvoid amytiss_vector_field(const double* x, const double* u, const double* w, double* rate) {\n"
           "  amytiss_rate_" + info_.name + "(x, u, w, rate);\n}\n";
  }

  std::string describe() const override { return "built-in " + info_.name; }

  std::optional<std::vector<VariableUse>> dependencies() const override { return source_.dependencies; }

 private:
  BuiltinModelInfo info_;
  const BuiltinSource& source_;
};

}  // namespace

std::unique_ptr<VectorField> make_builtin_field(const BuiltinModelInfo& info) {
  for (const auto& source : builtin_sources())
    if (source.name == info.name) return std::make_unique<BuiltinField>(info, source);
  return nullptr;
}

}  // namespace detail

const std::vector<BuiltinModelInfo>& builtin_models() {
  // Body of CommonRoad vehicle 2, overhangs taken equal: (4.508 - 2.578) / 2 = 0.965 m.
  constexpr double kLength = 4.508, kWidth = 1.610, kRearOverhang = 0.965;
  static const std::vector<BuiltinModelInfo> models = {
      {"bmw320i", 7, 2, 0,
       "BMW 320i single-track model with tire slip, Euler tau 0.1 s by default: x = (px, py of the centre of "
       "gravity, steering angle, velocity, yaw, yaw rate, slip angle), u = (steering velocity, acceleration)",
       BMW320I_TAU, VehicleOutline{0, 1, 4, kLength, kWidth, kRearOverhang + BMW320I_L_R}},
      {"bmw320i_ks", 5, 2, 0,
       "BMW 320i kinematic single-track model, Euler tau 0.1 s by default: x = (px, py of the rear axle, "
       "steering angle, velocity, yaw), u = (steering velocity, acceleration)",
       BMW320I_KS_TAU, VehicleOutline{0, 1, 4, kLength, kWidth, kRearOverhang}},
      {"vehicle3d", 3, 2, 0,
       "3-d vehicle of Reissig et al. 2016, Euler tau 0.3 s by default: x = (px, py, heading), u = (speed, "
       "steering angle)",
       VEHICLE3D_TAU, std::nullopt},
  };
  return models;
}

}  // namespace amytiss
