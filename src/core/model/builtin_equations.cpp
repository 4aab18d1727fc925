#include "model/builtin_equations.hpp"

#include <stdexcept>

namespace amytiss {

namespace {

// commonroad_vehicle2.h: Sat1 (steering velocity of angle x2, input u0) and Sat2 (acceleration of
// velocity x3, input u1), CommonRoad vehicle 2's limits written out.
const std::string kSaturatedSteering =
    "(((x2 <= -1.066 && u0 <= 0.0) || (x2 >= 1.066 && u0 >= 0.0)) ? 0.0 : "
    "(u0 <= -0.4 ? -0.4 : (u0 >= 0.4 ? 0.4 : u0)))";
const std::string kPositiveAccelerationLimit = "(x3 > 7.319 ? 11.5 * 7.319 / x3 : 11.5)";
const std::string kSaturatedAcceleration =
    "(((x3 <= -13.6 && u1 <= 0.0) || (x3 >= 50.8 && u1 >= 0.0)) ? 0.0 : (u1 <= -11.5 ? -11.5 : (u1 >= " +
    kPositiveAccelerationLimit + " ? " + kPositiveAccelerationLimit + " : u1)))";

std::vector<std::string> vehicle3d() {
  const std::string alpha = "atan(tan(u1) / 2.0)";
  return {"u0 * cos(" + alpha + " + x2) / cos(" + alpha + ")", "u0 * sin(" + alpha + " + x2) / cos(" + alpha + ")",
          "u0 * tan(u1)"};
}

std::vector<std::string> bmw320i_ks() {
  return {"x3 * cos(x4)", "x3 * sin(x4)", kSaturatedSteering, kSaturatedAcceleration,
          "x3 / (1.156 + 1.422) * tan(x2)"};
}

// bmw320i.h: the kinematic branch below |x3| < 0.1 m/s, the dynamic one above.
std::vector<std::string> bmw320i() {
  const std::string& steering = kSaturatedSteering;
  const std::string& acceleration = kSaturatedAcceleration;
  const std::string front = "(20.89 * (9.81 * 1.422 - " + acceleration + " * 0.6137))";
  const std::string rear = "(20.89 * (9.81 * 1.156 + " + acceleration + " * 0.6137))";
  const std::string axle_sum = "(1.422 + 1.156)";
  const std::string kinematic[7] = {
      "x3 * cos(x4)",
      "x3 * sin(x4)",
      steering,
      acceleration,
      "x3 / 2.5789 * tan(x2)",
      acceleration + " / 2.5789 * tan(x2) + x3 / (2.5789 * cos(x2) * cos(x2)) * " + steering,
      "0.0"};
  const std::string dynamic[7] = {
      "x3 * cos(x4 + x6)",
      "x3 * sin(x4 + x6)",
      steering,
      acceleration,
      "x5",
      "1.0489 * 1093.3 / (1791.6 * " + axle_sum + ") * (1.156 * " + front + " * x2 + (1.422 * " + rear +
          " - 1.156 * " + front + ") * x6 - (1.156 * 1.156 * " + front + " + 1.422 * 1.422 * " + rear +
          ") * x5 / x3)",
      "1.0489 / (x3 * " + axle_sum + ") * (" + front + " * x2 - (" + rear + " + " + front + ") * x6 + (1.422 * " +
          rear + " - 1.156 * " + front + ") * x5 / x3) - x5"};
  std::vector<std::string> rates;
  for (int i = 0; i < 7; ++i)
    rates.push_back(kinematic[i] == dynamic[i] ? kinematic[i]
                                               : "(abs(x3) < 0.1) ? " + kinematic[i] + " : " + dynamic[i]);
  return rates;
}

}  // namespace

std::vector<std::string> builtin_rate_equations(const std::string& model) {
  if (model == "vehicle3d") return vehicle3d();
  if (model == "bmw320i_ks") return bmw320i_ks();
  if (model == "bmw320i") return bmw320i();
  throw std::logic_error("builtin_rate_equations: no built-in model '" + model + "'");
}

}  // namespace amytiss
