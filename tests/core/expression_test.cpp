#include "core/expression.h"

#include <gtest/gtest.h>

#include <cmath>

#include "core/errors.h"
#include "core/scene.h"

namespace surge {
namespace {

double at(const std::string& text, double x, double y = 0, double z = 0) {
  return Expression(text)(Eigen::Vector3d(x, y, z));
}

std::string errorOf(const std::string& text) {
  try {
    Expression e(text);
  } catch (const ExpressionError& e) {
    return e.what();
  }
  return "no error";
}

// Precedence and associativity as in mathematics: * before +, ^ before unary minus (-2^2 = -4), ^ to the right
// (2^3^2 = 512), left-to-right for - and /. Values are exact in double precision, or one libm call each.
TEST(Expression, ReadsFormulasAsMathematicsDoes) {
  EXPECT_EQ(at("1 + 2 * 3", 0), 7);
  EXPECT_EQ(at("(1 + 2) * 3", 0), 9);
  EXPECT_EQ(at("8 - 3 - 2", 0), 3);
  EXPECT_EQ(at("16 / 4 / 2", 0), 2);
  EXPECT_EQ(at("-2^2", 0), -4);
  EXPECT_EQ(at("2^3^2", 0), 512);
  EXPECT_EQ(at("2^-1", 0), 0.5);
  EXPECT_EQ(at("1.5e2 + .5", 0), 150.5);
  EXPECT_EQ(at("x + 10*y + 100*z", 1, 2, 3), 321);
  EXPECT_EQ(at("-cos(2*pi*x)*sin(2*pi*y)", 0.125, 0.3), -std::cos(2 * M_PI * 0.125) * std::sin(2 * M_PI * 0.3));
  EXPECT_EQ(at("atan2(y, x)", 1, 1), std::atan2(1.0, 1.0));
  EXPECT_EQ(at("max(x, min(y, 3))", -1, 5), 3);
  EXPECT_EQ(at("sqrt(abs(x)) + exp(0) + log(1) + tanh(0) + floor(2.7)", -4), 5);
  EXPECT_EQ(at(" pow( 2 , 10 ) ", 0), 1024);
}

// What is wrong and where, counted in characters from 1.
TEST(Expression, RefusesWhatIsNotAFormulaSayingWhereAndWhy) {
  EXPECT_EQ(errorOf(""), "is empty at the end");
  EXPECT_EQ(errorOf("sin(x"), "')' expected at the end");
  EXPECT_EQ(errorOf("1 + q"), "unknown name 'q' (x, y, z, pi and functions such as sin, exp, sqrt, atan2, min) at character 5");
  EXPECT_EQ(errorOf("2 * * x"), "unexpected '*' at character 5");
  EXPECT_EQ(errorOf("x y"), "unexpected 'y' at character 3");
  EXPECT_EQ(errorOf("atan2(x)"), "',' expected (this function takes two arguments) at character 8");
  EXPECT_EQ(errorOf("sin x"), "'(' expected after a function at character 5");
  EXPECT_EQ(errorOf(std::string(200, '(') + "x" + std::string(200, ')')).rfind("nested too deeply", 0), 0u);
  EXPECT_EQ(errorOf(std::string(300, '-') + "x").rfind("nested too deeply", 0), 0u);
  EXPECT_EQ(errorOf(std::string(90, '(') + "x" + std::string(90, ')')), "no error");
}

// fluids[i].velocity_field in a scene: a number is a formula; the wrong count, a bad formula, one line naming the
// component's key; scene.json writes it back as read.
TEST(Expression, ASceneReadsAVelocityFieldNamingTheComponentAtFault) {
  const std::string base = R"({"name": "field", "dimensions": 2, "domain": {"min": [0, 0], "max": [1, 1]},
      "particle_spacing": 0.1, "fluids": [{"box": {"min": [0, 0], "max": [1, 1]}, "velocity_field": )";
  const Scene scene = parseScene(base + R"X(["sin(pi*y)", 2]}]})X", "field.json");
  ASSERT_EQ(scene.fluids[0].velocity_field.size(), 2u);
  EXPECT_EQ(scene.fluids[0].velocity_field[0], "sin(pi*y)");
  EXPECT_EQ(at(scene.fluids[0].velocity_field[1], 0), 2);
  EXPECT_EQ(parseScene(sceneToJson(scene), "scene.json").fluids[0].velocity_field, scene.fluids[0].velocity_field);
  const auto error = [&](const std::string& field) {
    try {
      parseScene(base + field + "}]}", "field.json");
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_EQ(error(R"(["x", "y +"])"),
            "field.json: fluids[0].velocity_field[1]: 'y +': a number, a name or '(' expected at the end");
  try {
    parseScene(base + R"(["x", "y"]}]})", "field.json", {R"X(fluids[0].velocity_field=["x", "(y"])X"});
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), "--set: fluids[0].velocity_field[1]: '(y': ')' expected at the end");
  }
  EXPECT_NE(error(R"(["x"])").find("fluids[0].velocity_field: expected an array of 2 formulas"), std::string::npos);
  EXPECT_NE(error(R"(["x", true])").find("fluids[0].velocity_field: expected formulas"), std::string::npos);
}

}  // namespace
}  // namespace surge
