// Dynamics expressions: grammar, evaluation, errors with columns, and the emitted C text.
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <string>

#include <gtest/gtest.h>

#include "amytiss/errors.hpp"
#include "amytiss/expression.hpp"

namespace amytiss {
namespace {

constexpr double kExact = 1e-15;

const std::map<std::string, double> kNoConstants;

double eval(const std::string& text, const std::vector<double>& x = {0.5, -2.0},
            const std::vector<double>& u = {3.0, 0.25}, const std::vector<double>& w = {0.125},
            const std::map<std::string, double>& constants = {{"tau", 10.0}}) {
  return Expression::parse(text, constants, 2, 2, 1).evaluate(x.data(), u.data(), w.data());
}

/// Column of the ParseError thrown by parsing `text` (2 states, 2 inputs, 1 disturbance), and its message.
std::pair<std::size_t, std::string> parse_error(const std::string& text) {
  try {
    Expression::parse(text, {{"tau", 10.0}}, 2, 2, 1);
  } catch (const ParseError& error) {
    return {error.column(), error.what()};
  }
  ADD_FAILURE() << "no ParseError for: " << text;
  return {0, ""};
}

TEST(Expression, Precedence) {
  EXPECT_NEAR(eval("1 + 2 * 3"), 7.0, kExact);
  EXPECT_NEAR(eval("(1 + 2) * 3"), 9.0, kExact);
  EXPECT_NEAR(eval("8 / 4 / 2"), 1.0, kExact);  // left-associative
  EXPECT_NEAR(eval("10 - 4 - 3"), 3.0, kExact);
  EXPECT_NEAR(eval("2 * 3 ^ 2"), 18.0, kExact);
  EXPECT_NEAR(eval("1 + 2 < 4 && 3 > 2"), 1.0, kExact);
}

TEST(Expression, UnaryMinus) {
  EXPECT_NEAR(eval("-x1"), 2.0, kExact);
  EXPECT_NEAR(eval("--3"), 3.0, kExact);
  EXPECT_NEAR(eval("-2^2"), -4.0, kExact);  // unary binds looser than ^
  EXPECT_NEAR(eval("2^-1"), 0.5, kExact);
  EXPECT_NEAR(eval("3 * -x0"), -1.5, kExact);
  EXPECT_NEAR(eval("+4"), 4.0, kExact);
}

TEST(Expression, PowerIsRightAssociative) {
  EXPECT_NEAR(eval("2^3^2"), 512.0, kExact);
  EXPECT_NEAR(eval("(2^3)^2"), 64.0, kExact);
}

TEST(Expression, NumbersVariablesConstants) {
  EXPECT_NEAR(eval("1.5e2 + .25 + 3."), 153.25, kExact);
  EXPECT_NEAR(eval("2E-1"), 0.2, kExact);
  EXPECT_NEAR(eval("x0 + x1 + u0 + u1 + w0"), 0.5 - 2.0 + 3.0 + 0.25 + 0.125, kExact);
  EXPECT_NEAR(eval("tau * 2"), 20.0, kExact);
  EXPECT_NEAR(eval("pi"), M_PI, kExact);
  // The robot dynamics of the paper.
  EXPECT_NEAR(eval("x0 + tau*u0*cos(u1) + w0"), 0.5 + 10.0 * 3.0 * std::cos(0.25) + 0.125, kExact);
}

TEST(Expression, Functions) {
  const double a = 0.3;
  EXPECT_NEAR(eval("sin(0.3)"), std::sin(a), kExact);
  EXPECT_NEAR(eval("cos(0.3)"), std::cos(a), kExact);
  EXPECT_NEAR(eval("tan(0.3)"), std::tan(a), kExact);
  EXPECT_NEAR(eval("asin(0.3)"), std::asin(a), kExact);
  EXPECT_NEAR(eval("acos(0.3)"), std::acos(a), kExact);
  EXPECT_NEAR(eval("atan(0.3)"), std::atan(a), kExact);
  EXPECT_NEAR(eval("atan2(1, -1)"), std::atan2(1.0, -1.0), kExact);
  EXPECT_NEAR(eval("exp(0.3)"), std::exp(a), kExact);
  EXPECT_NEAR(eval("log(0.3)"), std::log(a), kExact);
  EXPECT_NEAR(eval("sqrt(0.3)"), std::sqrt(a), kExact);
  EXPECT_NEAR(eval("pow(2, 0.5)"), std::sqrt(2.0), kExact);
  EXPECT_NEAR(eval("abs(x1)"), 2.0, kExact);
  EXPECT_NEAR(eval("min(x0, x1)"), -2.0, kExact);
  EXPECT_NEAR(eval("max(x0, x1)"), 0.5, kExact);
  EXPECT_NEAR(eval("floor(-1.5)"), -2.0, kExact);
  EXPECT_NEAR(eval("ceil(-1.5)"), -1.0, kExact);
}

TEST(Expression, ConditionalAndComparisons) {
  EXPECT_NEAR(eval("x0 > 0 ? 1 : 2"), 1.0, kExact);
  EXPECT_NEAR(eval("x1 > 0 ? 1 : 2"), 2.0, kExact);
  EXPECT_NEAR(eval("if(abs(x1) < 0.1, 7, 8)"), 8.0, kExact);
  EXPECT_NEAR(eval("if(0.5, 7, 8)"), 7.0, kExact);  // any non-zero condition is true
  EXPECT_NEAR(eval("x0 < 0 ? 1 : x0 < 1 ? 2 : 3"), 2.0, kExact);  // nests to the right
  EXPECT_NEAR(eval("1 <= 1"), 1.0, kExact);
  EXPECT_NEAR(eval("1 < 1"), 0.0, kExact);
  EXPECT_NEAR(eval("2 >= 3"), 0.0, kExact);
  EXPECT_NEAR(eval("2 == 2"), 1.0, kExact);
  EXPECT_NEAR(eval("2 != 2"), 0.0, kExact);
  EXPECT_NEAR(eval("0 || 3"), 1.0, kExact);
  EXPECT_NEAR(eval("1 && 0"), 0.0, kExact);
  EXPECT_NEAR(eval("!0"), 1.0, kExact);
  EXPECT_NEAR(eval("!x0"), 0.0, kExact);
}

TEST(Expression, ErrorColumns) {
  auto [column, message] = parse_error("cos(x0");
  EXPECT_EQ(column, 7u);
  EXPECT_NE(message.find("column 7: expected ')' after argument list of cos"), std::string::npos) << message;

  std::tie(column, message) = parse_error("x0 + foo");
  EXPECT_EQ(column, 6u);
  EXPECT_NE(message.find("unknown name 'foo'"), std::string::npos) << message;

  std::tie(column, message) = parse_error("x0 + x5");
  EXPECT_EQ(column, 6u);
  EXPECT_NE(message.find("'x5' is out of range"), std::string::npos) << message;
  EXPECT_NE(message.find("x0..x1"), std::string::npos) << message;

  std::tie(column, message) = parse_error("u2");
  EXPECT_EQ(column, 1u);
  std::tie(column, message) = parse_error("w1");
  EXPECT_EQ(column, 1u);

  std::tie(column, message) = parse_error("atan2(x0)");
  EXPECT_EQ(column, 1u);
  EXPECT_NE(message.find("atan2 takes 2 arguments, got 1"), std::string::npos) << message;

  std::tie(column, message) = parse_error("atan2(x0 x1)");
  EXPECT_EQ(column, 10u);
  EXPECT_NE(message.find("expected ',' and the next argument of atan2"), std::string::npos) << message;

  std::tie(column, message) = parse_error("sin(x0, x1)");
  EXPECT_EQ(column, 1u);
  EXPECT_NE(message.find("sin takes 1 argument, got 2"), std::string::npos) << message;

  std::tie(column, message) = parse_error("x0 +");
  EXPECT_EQ(column, 5u);
  EXPECT_NE(message.find("expected a number, a variable"), std::string::npos) << message;

  std::tie(column, message) = parse_error("(x0 + 1");
  EXPECT_EQ(column, 8u);
  EXPECT_NE(message.find("expected ')' to close '(' at column 1"), std::string::npos) << message;

  std::tie(column, message) = parse_error("x0 x1");
  EXPECT_EQ(column, 4u);
  EXPECT_NE(message.find("expected an operator"), std::string::npos) << message;

  std::tie(column, message) = parse_error("x0 = 1");
  EXPECT_EQ(column, 4u);
  EXPECT_NE(message.find("did you mean '=='"), std::string::npos) << message;

  std::tie(column, message) = parse_error("x0 > 0 ? 1");
  EXPECT_EQ(column, 11u);
  EXPECT_NE(message.find("expected ':'"), std::string::npos) << message;

  std::tie(column, message) = parse_error("sin x0");
  EXPECT_EQ(column, 5u);
  EXPECT_NE(message.find("expected '(' after function name sin"), std::string::npos) << message;

  std::tie(column, message) = parse_error("1e+");
  EXPECT_EQ(column, 4u);

  std::tie(column, message) = parse_error("");
  EXPECT_EQ(column, 1u);

  std::tie(column, message) = parse_error("system(\"rm\")");
  EXPECT_EQ(column, 1u);
  EXPECT_NE(message.find("unknown name 'system'"), std::string::npos) << message;

  std::tie(column, message) = parse_error("x0 + #");
  EXPECT_EQ(column, 6u);
  EXPECT_NE(message.find("unexpected character '#'"), std::string::npos) << message;

  std::tie(column, message) = parse_error("1 < 2 < 3");
  EXPECT_EQ(column, 7u);
}

TEST(Expression, AutonomousSystemHasNoInputs) {
  try {
    Expression::parse("0.8*x0 + u0", kNoConstants, 1, 0, 0);
    FAIL() << "u0 accepted without inputs";
  } catch (const ParseError& error) {
    EXPECT_EQ(error.column(), 10u);
    EXPECT_NE(std::string(error.what()).find("no input components"), std::string::npos) << error.what();
  }
}

TEST(Expression, ToCText) {
  const auto c = [](const std::string& text) { return Expression::parse(text, {{"tau", 10.0}}, 2, 2, 1).to_c(); };
  EXPECT_EQ(c("x0 + tau*u0*cos(u1)"), "(x[0] + (10.0 * u[0] * cos(u[1])))");
  EXPECT_EQ(c("abs(x1) + min(x0, 1) + max(w0, 2)"), "(fabs(x[1]) + fmin(x[0], 1.0) + fmax(w[0], 2.0))");
  EXPECT_EQ(c("x0^2"), "pow(x[0], 2.0)");
  EXPECT_EQ(c("if(x0 < 1, 2, 3)"), "((((double)(x[0] < 1.0)) != 0.0) ? 2.0 : 3.0)");
  // The shortest text that reads back to the same double.
  EXPECT_EQ(c("0.1"), "0.1");
  EXPECT_EQ(c("1e300"), "1e+300");
  EXPECT_EQ(c("0.30000000000000004"), "0.30000000000000004");
  EXPECT_EQ(c("-x0"), "(-x[0])");
}

// Compiles the emitted C with the system compiler and checks it computes what evaluate() does.
TEST(Expression, ToCCompilesAndAgrees) {
  const std::vector<std::string> texts = {
      "x0 + tau*u0*cos(u1) + w0", "x1 + tau*u0*sin(u1) + w0", "2^3^2 - -x1", "x0 > 0 && !(x1 > 0) ? atan2(x0, x1) : 0",
      "if(abs(x1) < 0.1, floor(x0), ceil(x1)) + sqrt(exp(log(2))) + pow(u1, 2) + asin(0.5) + acos(0.5) + tan(atan(u1))",
      "(x0 >= 1) + (x0 <= 1) + (x0 == 0.5) + (x0 != 0.5) + (0 || x0) + min(x0, x1) * max(x0, x1) / 3"};
  const std::string dir = ::testing::TempDir();
  const std::string source_path = dir + "/amytiss_expr_check.c";
  const std::string binary_path = dir + "/amytiss_expr_check";
  {
    std::ofstream source(source_path);
    source << "#include <math.h>\n#include <stdio.h>\nint main(void) {\n"
              "  const double x[2] = {0.5, -2.0}, u[2] = {3.0, 0.25}, w[1] = {0.125};\n";
    for (const auto& text : texts)
      source << "  printf(\"%.17g\\n\", " << Expression::parse(text, {{"tau", 10.0}}, 2, 2, 1).to_c() << ");\n";
    source << "  return 0;\n}\n";
  }
  if (std::system(("cc -std=c99 -Wall -Werror -o " + binary_path + " " + source_path + " -lm").c_str()) != 0)
    GTEST_SKIP() << "no C compiler (cc) to check the emitted text";
  FILE* pipe = popen(binary_path.c_str(), "r");
  ASSERT_NE(pipe, nullptr);
  for (const auto& text : texts) {
    double compiled = 0;
    ASSERT_EQ(std::fscanf(pipe, "%lf", &compiled), 1);
    EXPECT_NEAR(compiled, eval(text), 1e-12) << text;
  }
  pclose(pipe);
}

}  // namespace
}  // namespace amytiss
