#pragma once
// One fuzz input through the expression parser and the configuration reader + validation. Shared
// by the libFuzzer target (test/fuzz/fuzz_config.cpp, run by scripts/fuzz) and the gtest that
// replays the seed corpus and every kept crasher (test/core/test_fuzz_regressions.cpp).
//
// Input: the first byte picks the path; the rest is text.
//   even: a dynamics expression over 2 states, 2 inputs, 1 disturbance and the constant `tau`,
//         parsed, evaluated at a fixed point and emitted as C;
//   odd:  a YAML configuration, read (and written back), validated, written back as canonical
//         YAML and hashed.
// Refusals (ParseError, ConfigError, YAML::Exception) are the expected outcome of bad input; any
// other exception, a crash or a sanitizer report is a finding.
#include <cstddef>
#include <cstdint>
#include <map>
#include <string>

#include <yaml-cpp/yaml.h>

#include "amytiss/config.hpp"
#include "amytiss/errors.hpp"
#include "amytiss/expression.hpp"

namespace amytiss {

inline void fuzz_one_input(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return;
  const std::string text(reinterpret_cast<const char*>(data) + 1, size - 1);
  try {
    if (data[0] % 2 == 0) {
      const Expression expression = Expression::parse(text, {{"tau", 10.0}}, 2, 2, 1);
      const double x[2] = {0.5, -2.0}, u[2] = {3.0, 0.25}, w[1] = {0.125};
      volatile double value = expression.evaluate(x, u, w);
      (void)value;
      volatile std::size_t length = expression.to_c().size();
      (void)length;
    } else {
      // The reader alone first (it must take any value of the right type without judging it),
      // then the one validation.
      Config config = read_config(YAML::Load(text));
      volatile std::size_t read_length = to_yaml(config).size();
      (void)read_length;
      config.validate();
      volatile std::size_t length = to_yaml(config).size() + config_hash(config).size();
      (void)length;
    }
  } catch (const ParseError&) {
  } catch (const ConfigError&) {
  } catch (const YAML::Exception&) {
  }
}

}  // namespace amytiss
