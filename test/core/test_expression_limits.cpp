// Inputs that once crashed the parser (stack overflow in parse, evaluate, to_c or the node
// destructor) are refused with a ParseError that names the limit; inputs just inside the limits
// still parse and evaluate exactly. Crash inputs found by the fuzzer (scripts/fuzz) are replayed
// from test/fuzz/regressions/.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "amytiss/config.hpp"
#include "amytiss/errors.hpp"
#include "amytiss/expression.hpp"

namespace amytiss {
namespace {

namespace fs = std::filesystem;

constexpr double kExact = 0.0;

std::string repeat(const std::string& piece, std::size_t times) {
  std::string text;
  text.reserve(piece.size() * times);
  for (std::size_t i = 0; i < times; ++i) text += piece;
  return text;
}

/// The message of the ParseError thrown by parsing `text` (2 states, 1 input), or "" if none.
std::string parse_error(const std::string& text) {
  try {
    Expression::parse(text, {}, 2, 1, 0);
  } catch (const ParseError& error) {
    return error.what();
  }
  return "";
}

#define EXPECT_CONTAINS(haystack, needle) \
  EXPECT_NE(std::string::npos, (haystack).find(needle)) << "missing '" << (needle) << "' in:\n" << (haystack)

const std::string kDepthLimit = "nested deeper than the limit of " + std::to_string(kMaxExpressionDepth) + " levels";

TEST(ExpressionLimits, TenThousandNestedParentheses) {
  EXPECT_CONTAINS(parse_error(repeat("(", 10000) + "x0" + repeat(")", 10000)), kDepthLimit);
}

TEST(ExpressionLimits, HundredThousandUnaryMinus) {
  EXPECT_CONTAINS(parse_error(repeat("-", 100000) + "x0"), "100002 characters long");
  EXPECT_CONTAINS(parse_error(repeat("-", 60000) + "x0"), kDepthLimit);
  EXPECT_CONTAINS(parse_error(repeat("!", 60000) + "x0"), kDepthLimit);
}

TEST(ExpressionLimits, AbsNestedHundredThousandDeep) {
  // 500,000 characters: the length limit answers first, naming both lengths.
  const std::string text = repeat("abs(", 100000) + "x0" + repeat(")", 100000);
  const std::string message = parse_error(text);
  EXPECT_CONTAINS(message, std::to_string(text.size()) + " characters long");
  EXPECT_CONTAINS(message, "limit of " + std::to_string(kMaxExpressionLength));
  // Within the length limit, the depth limit answers.
  EXPECT_CONTAINS(parse_error(repeat("abs(", 10000) + "x0" + repeat(")", 10000)), kDepthLimit);
}

TEST(ExpressionLimits, RepeatedPower) {
  EXPECT_CONTAINS(parse_error("x0" + repeat("^1", 30000)), kDepthLimit);
}

TEST(ExpressionLimits, TenMegabyteFlatSum) {
  const std::string text = "x0" + repeat(" + x0", 2 * 1024 * 1024);
  const std::string message = parse_error(text);
  EXPECT_CONTAINS(message, "column " + std::to_string(kMaxExpressionLength + 1));
  EXPECT_CONTAINS(message, std::to_string(text.size()) + " characters long");
}

TEST(ExpressionLimits, NodeCount) {
  EXPECT_CONTAINS(parse_error("1" + repeat("+1", kMaxExpressionNodes)),
                  "more than the limit of " + std::to_string(kMaxExpressionNodes) + " terms");
}

TEST(ExpressionLimits, LongFlatChainsInsideTheLimitsEvaluateAsLoops) {
  const double x[2] = {0.5, -2.0}, u[1] = {3.0};
  const std::size_t terms = kMaxExpressionNodes / 2;
  const Expression sum = Expression::parse("x0" + repeat("+x0", terms - 1), {}, 2, 1, 0);
  EXPECT_NEAR(sum.evaluate(x, u, nullptr), 0.5 * terms, kExact);
  EXPECT_EQ(std::string::npos, sum.to_c().find("((")) << "a flat sum is emitted without nesting";
  const Expression product = Expression::parse("1" + repeat("*u0/u0", 2000), {}, 2, 1, 0);
  EXPECT_NEAR(product.evaluate(x, u, nullptr), 1.0, 1e-12);
  const Expression logical = Expression::parse("1" + repeat(" && x0", 3000) + " || 0", {}, 2, 1, 0);
  EXPECT_NEAR(logical.evaluate(x, u, nullptr), 1.0, kExact);
}

TEST(ExpressionLimits, NestingJustInsideTheLimitParses) {
  // Each parenthesis costs two levels (the sub-expression and its operand).
  const std::size_t depth = kMaxExpressionDepth / 2 - 2;
  const double x[2] = {0.5, -2.0}, u[1] = {3.0};
  const Expression nested = Expression::parse(repeat("(", depth) + "x0" + repeat(")", depth), {}, 2, 1, 0);
  EXPECT_NEAR(nested.evaluate(x, u, nullptr), 0.5, kExact);
  const Expression negated = Expression::parse(repeat("-", kMaxExpressionDepth / 2) + "x1", {}, 2, 1, 0);
  EXPECT_NEAR(negated.evaluate(x, u, nullptr), -2.0, kExact);
}

/// A valid configuration (cli_tiny.yaml) whose first dynamics expression is `dynamics0`.
std::string config_with_dynamics(const std::string& dynamics0) {
  return "name: limits\nstates: {lb: [-4, -4], ub: [4, 4], eta: [1, 1]}\n"
         "inputs: {lb: [-1, -1], ub: [1, 1], eta: [1, 1]}\n"
         "dynamics: [\"" + dynamics0 + "\", \"x1 + u1\"]\n"
         "noise: {type: additive, distribution: normal, covariance: [0.2, 0.2]}\n"
         "spec: {type: safety, horizon: 4}\ncompute: {device: reference}\n";
}

TEST(ExpressionLimits, ConfigurationNamesTheKeyAndKeepsTheMessageShort) {
  constexpr std::size_t kMaxMessage = 600;  // the expression is shown abbreviated
  try {
    config_from_yaml(YAML::Load(config_with_dynamics(repeat("(", 10000) + "x0" + repeat(")", 10000))));
    FAIL() << "accepted";
  } catch (const ConfigError& error) {
    EXPECT_EQ("dynamics[0]", error.key());
    EXPECT_CONTAINS(std::string(error.what()), kDepthLimit);
    EXPECT_CONTAINS(std::string(error.what()), "(20002 characters)");
    EXPECT_LT(std::string(error.what()).size(), kMaxMessage);
  }
}

TEST(ExpressionLimits, CommandLineToolRefusesWithoutCrashing) {
  const fs::path directory = fs::temp_directory_path() / ("amytiss_limits_" + std::to_string(::getpid()));
  fs::create_directories(directory);
  const std::vector<std::string> hostile = {repeat("(", 10000) + "x0" + repeat(")", 10000),
                                            repeat("-", 100000) + "x0", "x0" + repeat("^1", 30000),
                                            "x0" + repeat(" + x0", 2 * 1024 * 1024)};
  for (std::size_t i = 0; i < hostile.size(); ++i) {
    const fs::path config = directory / ("hostile" + std::to_string(i) + ".yaml");
    std::ofstream(config) << config_with_dynamics(hostile[i]);
    const std::string command = std::string("'") + AMYTISS_SYNTH_BIN + "' --config '" + config.string() +
                                "' --output '" + (directory / "out.h5").string() + "' >/dev/null 2>'" +
                                (directory / "err.txt").string() + "'";
    const int status = std::system(command.c_str());
    ASSERT_TRUE(WIFEXITED(status)) << "killed by a signal on input " << i;
    EXPECT_NE(0, WEXITSTATUS(status)) << "accepted input " << i;
    std::stringstream err;
    err << std::ifstream(directory / "err.txt").rdbuf();
    EXPECT_CONTAINS(err.str(), "dynamics[0]");
  }
  fs::remove_all(directory);
}

}  // namespace
}  // namespace amytiss
