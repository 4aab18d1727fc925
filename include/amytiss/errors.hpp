#pragma once
// Exceptions thrown by the amytiss core for failures a user can meet, each with a message meant for
// the user. The core never exits or logs-and-continues. Besides these: std::logic_error when an
// invariant a validated configuration guarantees does not hold (a bug of the caller),
// std::invalid_argument for an argument outside a utility's domain (normal_upper_quantile), and
// ExportTooLarge (model_export.hpp) for a model export over its limit.
#include <stdexcept>
#include <string>

namespace amytiss {

/// A configuration value is missing or invalid. what() names the key, the value received and an
/// example of a valid value, e.g.
///   "states.eta[1]: got -0.5, expected a positive number (example: eta: [0.5, 0.5])".
class ConfigError : public std::runtime_error {
 public:
  ConfigError(const std::string& key, const std::string& message)
      : std::runtime_error(key + ": " + message), key_(key) {}
  /// The dotted configuration key at fault, e.g. "noise.covariance".
  const std::string& key() const { return key_; }

 private:
  std::string key_;
};

/// A dynamics expression does not parse. what() says the column (1-based) and what was expected.
class ParseError : public std::runtime_error {
 public:
  ParseError(std::size_t column, const std::string& message)
      : std::runtime_error("column " + std::to_string(column) + ": " + message), column_(column) {}
  std::size_t column() const { return column_; }

 private:
  std::size_t column_;
};

/// A policy file cannot be read: missing, truncated, corrupt, of another format version, or made
/// from another configuration.
class PolicyFileError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// An OpenCL device could not be found, set up, or failed while running (kernel build errors
/// carry the compiler's log), or a device request cannot be honoured on this machine (absent
/// kind, unmatched selection, stored transitions that do not fit: the message starts with the
/// key, e.g. "compute.device: got gpu, but ...", and names the devices present).
class DeviceError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Synthesis was cancelled through the progress callback.
class Cancelled : public std::runtime_error {
 public:
  Cancelled() : std::runtime_error("synthesis cancelled") {}
};

}  // namespace amytiss
