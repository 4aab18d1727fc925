#include "amytiss/enclosure.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "amytiss/expression.hpp"
#include "amytiss/model.hpp"
#include "model/builtin_equations.hpp"
#include "model/expression_interval.hpp"

namespace amytiss {

using Jets = std::vector<IntervalJet>;

namespace {

// from + length * rate, coordinate by coordinate: one stage of integrator.h.
Jets moved(const Jets& from, const IntervalJet& length, const Jets& rate) {
  Jets to;
  to.reserve(from.size());
  for (std::size_t i = 0; i < from.size(); ++i) to.push_back(from[i] + length * rate[i]);
  return to;
}

}  // namespace

/// The system map over jets: the expressions themselves, or the integrator (models/integrator.h)
/// replayed over jets with the expressions as dx/dt, operation for operation.
struct ImageEnclosure::Map {
  std::size_t state_dims = 0, input_dims = 0, disturbance_dims = 0;
  std::vector<IntervalExpression> expressions;
  bool integrated = false;
  IntegrationMethod method = IntegrationMethod::Euler;
  unsigned substeps = 1;
  double tau = 0.0;

  Jets evaluate(const Jets& x, const Jets& u, const Jets& w, std::size_t dims) const {
    Jets out;
    for (const IntervalExpression& expression : expressions)
      out.push_back(expression.evaluate(x.data(), u.data(), w.data(), dims));
    return out;
  }

  Jets step(const Jets& x, const Jets& u, const Jets& w, std::size_t dims) const {
    if (!integrated) return evaluate(x, u, w, dims);
    const double h = tau / substeps;  // as integrator.h computes it
    const auto constant = [dims](const Interval& value) { return IntervalJet::constant(value, dims); };
    const IntervalJet step_length = constant(Interval::point(h));
    const IntervalJet half_step = constant(Interval::point(0.5) * Interval::point(h));
    const IntervalJet sixth_step = constant(Interval::point(h) / Interval::point(6.0));
    const IntervalJet two = constant(Interval::point(2.0));
    Jets state = x;
    for (unsigned s = 0; s < substeps; ++s) {
      const Jets k1 = evaluate(state, u, w, dims);
      if (method == IntegrationMethod::Euler) {
        state = moved(state, step_length, k1);
        continue;
      }
      const Jets k2 = evaluate(moved(state, half_step, k1), u, w, dims);
      const Jets k3 = evaluate(moved(state, half_step, k2), u, w, dims);
      const Jets k4 = evaluate(moved(state, step_length, k3), u, w, dims);
      for (std::size_t i = 0; i < state.size(); ++i)
        state[i] = state[i] + sixth_step * (k1[i] + two * k2[i] + two * k3[i] + k4[i]);
    }
    return state;
  }

  void check(const IntervalBox& cell, const std::vector<double>& u, const IntervalBox& w) const {
    if (cell.size() != state_dims || u.size() != input_dims || w.size() != disturbance_dims)
      throw std::logic_error("ImageEnclosure: expected a cell of " + std::to_string(state_dims) + " states, " +
                             std::to_string(input_dims) + " inputs and " + std::to_string(disturbance_dims) +
                             " disturbances");
  }

  Jets points(const std::vector<double>& values, std::size_t dims) const {
    Jets jets;
    for (double value : values) jets.push_back(IntervalJet::constant(Interval::point(value), dims));
    return jets;
  }
  // The disturbance enters like an input that ranges over an interval: no gradient (the
  // enclosures' derivatives are in x only).
  Jets ranges(const IntervalBox& values, std::size_t dims) const {
    Jets jets;
    for (const Interval& value : values) jets.push_back(IntervalJet::constant(value, dims));
    return jets;
  }

  // f over the cell and the disturbances' box; with gradients (dims = state_dims) or without (dims = 0).
  Jets over(const IntervalBox& cell, const std::vector<double>& u, const IntervalBox& w, bool gradients) const {
    check(cell, u, w);
    const std::size_t dims = gradients ? state_dims : 0;
    Jets x;
    for (std::size_t j = 0; j < cell.size(); ++j)
      x.push_back(gradients ? IntervalJet::variable(cell[j], j, dims) : IntervalJet::constant(cell[j], 0));
    return step(x, points(u, dims), ranges(w, dims), dims);
  }
};

namespace {

ImageBox image_of(const Jets& jets) {
  ImageBox image;
  for (const IntervalJet& jet : jets) {
    image.box.push_back(jet.value);
    image.defined = image.defined && jet.value.defined;
  }
  return image;
}

}  // namespace

ImageEnclosure::ImageEnclosure(const Config& config) {
  auto map = std::make_unique<Map>();
  map->state_dims = config.states.lb.size();
  map->input_dims = config.inputs ? config.inputs->lb.size() : 0;
  map->disturbance_dims = config.disturbances ? config.disturbances->lb.size() : 0;
  map->method = config.integrator.method;
  map->substeps = config.integrator.substeps;
  if (config.model.empty()) {
    for (const Expression& expression : parse_dynamics(config)) map->expressions.emplace_back(expression);
    map->integrated = config.integrator.tau.has_value();
    map->tau = config.integrator.tau.value_or(0.0);
  } else {
    for (const auto& info : builtin_models())
      if (info.name == config.model) map->tau = config.integrator.tau.value_or(info.tau);
    for (const std::string& text : builtin_rate_equations(config.model))
      map->expressions.emplace_back(
          Expression::parse(text, {}, map->state_dims, map->input_dims, map->disturbance_dims));
    map->integrated = true;
  }
  if (map->expressions.size() != map->state_dims)
    throw std::logic_error("ImageEnclosure: expected a validated configuration (one equation per state)");
  map_ = std::move(map);
}

ImageEnclosure::~ImageEnclosure() = default;
ImageEnclosure::ImageEnclosure(ImageEnclosure&&) noexcept = default;
ImageEnclosure& ImageEnclosure::operator=(ImageEnclosure&&) noexcept = default;

std::size_t ImageEnclosure::state_dims() const { return map_->state_dims; }
std::size_t ImageEnclosure::input_dims() const { return map_->input_dims; }
std::size_t ImageEnclosure::disturbance_dims() const { return map_->disturbance_dims; }

namespace {
IntervalBox point_box(const std::vector<double>& values) {
  IntervalBox box;
  for (double value : values) box.push_back(Interval::point(value));
  return box;
}
}  // namespace

ImageBox ImageEnclosure::natural(const IntervalBox& cell, const std::vector<double>& u, const std::vector<double>& w) const {
  return natural_over(cell, u, point_box(w));
}

ImageBox ImageEnclosure::natural_over(const IntervalBox& cell, const std::vector<double>& u,
                                      const IntervalBox& w) const {
  return image_of(map_->over(cell, u, w, false));
}

IntervalJacobian ImageEnclosure::jacobian(const IntervalBox& cell, const std::vector<double>& u,
                                          const std::vector<double>& w) const {
  IntervalJacobian jacobian;
  for (const IntervalJet& jet : map_->over(cell, u, point_box(w), true)) {
    jacobian.entries.push_back(jet.gradient);
    jacobian.valid.push_back(jet.smooth);
  }
  return jacobian;
}

ImageBox ImageEnclosure::enclose(const IntervalBox& cell, const std::vector<double>& u, const std::vector<double>& w) const {
  return enclose_over(cell, u, point_box(w));
}

// Mean-value theorem (Lebourg's for the Lipschitz |.|, min, max), at each fixed w of W: f_i(x, w) -
// f_i(c, w) lies in sum_j J_ij(X, W) (x_j - c_j) for x in X, so f_i(X, W) lies in
// f_i(c, W) + sum_j J_ij(X, W) (X_j - c_j).
ImageBox ImageEnclosure::enclose_over(const IntervalBox& cell, const std::vector<double>& u,
                                      const IntervalBox& w) const {
  const Jets jets = map_->over(cell, u, w, true);
  IntervalBox centre_box;
  for (const Interval& component : cell) centre_box.push_back(Interval::point(component.mid()));
  const Jets at_centre = map_->over(centre_box, u, w, false);
  ImageBox image = image_of(jets);
  for (std::size_t i = 0; i < jets.size(); ++i) {
    // Lebourg's theorem along x_i: f_i(x + d e_i) - f_i(x) lies in J_ii(X) d, so a J_ii of one
    // sign moves f_i by at least its least magnitude times |d|.
    const Interval& own = jets[i].gradient[i];
    const bool one_sign = jets[i].smooth && !own.is_empty() && !own.contains_zero();
    image.expansion.push_back(one_sign ? std::min(std::fabs(own.lo), std::fabs(own.hi)) : 0.0);
    if (!jets[i].smooth || !at_centre[i].value.defined) continue;
    Interval centred = at_centre[i].value;
    for (std::size_t j = 0; j < cell.size(); ++j) centred = centred + jets[i].gradient[j] * (cell[j] - centre_box[j]);
    const Interval both = intersect(image.box[i], centred);
    if (!both.is_empty()) image.box[i] = both;
  }
  return image;
}

}  // namespace amytiss
