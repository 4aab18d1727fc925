// The integrator (models/integrator.h) stepping a vector field, on the host and as OpenCL C.
#include "model/integrated_dynamics.hpp"

#include <algorithm>
#include <string>

#include "amytiss/format.hpp"
#include "common/embedded_sources.hpp"

namespace amytiss {
namespace builtin {
// The integrator calls the vector field through the object it is given (OpenCL: a plain function).
#include "model/models/model_function.h"
#define AMYTISS_INTEGRATOR_CAPACITY 32
#define AMYTISS_VECTOR_FIELD_CONTEXT const ::amytiss::VectorField *field,
#define AMYTISS_VECTOR_FIELD(x_, u_, w_, rate_) field->rate(x_, u_, w_, rate_)
#include "model/models/integrator.h"
static_assert(AMYTISS_INTEGRATOR_CAPACITY == kMaxIntegratorStates, "stage arrays hold every integrated state");
}  // namespace builtin

namespace {

std::vector<std::size_t> merged(std::vector<std::size_t> a, const std::vector<std::size_t>& b) {
  a.insert(a.end(), b.begin(), b.end());
  std::sort(a.begin(), a.end());
  a.erase(std::unique(a.begin(), a.end()), a.end());
  return a;
}

}  // namespace

std::vector<VariableUse> integrated_dependencies(const std::vector<VariableUse>& field,
                                                 const IntegratorConfig& integrator) {
  const bool one_stage = integrator.method == IntegrationMethod::Euler && integrator.substeps == 1;
  std::vector<VariableUse> uses(field.size());
  for (std::size_t i = 0; i < field.size(); ++i) {
    // One Euler stage: post_i = x_i + h g_i(x). Every later stage evaluates g_i at a state whose
    // coordinates j were moved by h g_j, so coordinate i reads what those g_j read, transitively.
    std::vector<std::size_t> reached{i};
    for (std::size_t next = 0; next < reached.size(); ++next) {
      const VariableUse& rate = field[reached[next]];
      uses[i].inputs = merged(uses[i].inputs, rate.inputs);
      uses[i].disturbances = merged(uses[i].disturbances, rate.disturbances);
      for (std::size_t k : rate.states)
        if (std::find(reached.begin(), reached.end(), k) == reached.end()) reached.push_back(k);
      if (one_stage) break;
    }
    uses[i].states = merged(reached, {});
  }
  return uses;
}

namespace detail {
namespace {

/// x(k+1) = the integrator's step of length tau applied to a vector field (models/integrator.h).
class IntegratedDynamics : public Dynamics {
 public:
  IntegratedDynamics(std::unique_ptr<VectorField> field, const IntegratorConfig& integrator, double tau)
      : field_(std::move(field)), integrator_(integrator), tau_(tau) {}

  std::size_t state_dims() const override { return field_->state_dims(); }
  std::size_t input_dims() const override { return field_->input_dims(); }
  std::size_t disturbance_dims() const override { return field_->disturbance_dims(); }

  void evaluate(const double* x, const double* u, const double* w, double* post) const override {
    builtin::amytiss_integrate(field_.get(), x, u, w, static_cast<int>(state_dims()), tau_, method_code(),
                               static_cast<int>(integrator_.substeps), post);
  }

  std::string opencl_source() const override {
    return field_->opencl_source() + embedded_source("model_function.h") +
           "\n#define AMYTISS_INTEGRATOR_CAPACITY " + std::to_string(state_dims()) +
           "\n#define AMYTISS_VECTOR_FIELD_CONTEXT\n"
           "#define AMYTISS_VECTOR_FIELD(x_, u_, w_, rate_) amytiss_vector_field(x_, u_, w_, rate_)\n" +
           embedded_source("integrator.h") +
           "\nvoid amytiss_dynamics(const double* x, const double* u, const double* w, double* post) {\n"
           "  amytiss_integrate(x, u, w, " + std::to_string(state_dims()) + ", " + c_double_literal(tau_) + ", " +
           std::to_string(method_code()) + ", " + std::to_string(integrator_.substeps) + ", post);\n}\n";
  }

  std::string describe() const override {
    if (integrator_.is_default()) return field_->describe();
    return field_->describe() + ", " + to_string(integrator_.method) + " x" + std::to_string(integrator_.substeps) +
           " per step of " + format_number(tau_) + " s";
  }

  std::optional<std::vector<VariableUse>> dependencies() const override {
    const auto uses = field_->dependencies();
    if (!uses) return std::nullopt;
    return integrated_dependencies(*uses, integrator_);
  }

 private:
  int method_code() const {
    return integrator_.method == IntegrationMethod::Rk4 ? AMYTISS_INTEGRATOR_RK4 : AMYTISS_INTEGRATOR_EULER;
  }

  std::unique_ptr<VectorField> field_;
  IntegratorConfig integrator_;
  double tau_;
};

}  // namespace

std::unique_ptr<Dynamics> make_integrated_dynamics(std::unique_ptr<VectorField> field,
                                                   const IntegratorConfig& integrator, double tau) {
  return std::make_unique<IntegratedDynamics>(std::move(field), integrator, tau);
}

}  // namespace detail
}  // namespace amytiss
