// A formula of a point, such as "-cos(2*pi*x)*sin(2*pi*y)": the scene's way to give a field (an initial velocity)
// without code. Numbers, x, y, z, pi, + - * / ^ (right-associative), parentheses, and the functions listed in
// expression.cpp. Parsed once into a postfix program; evaluated in double precision.
#pragma once

#include <stdexcept>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace surge {

class Expression {
 public:
  // Throws ExpressionError on text that is not a formula.
  explicit Expression(const std::string& text);

  double operator()(const Eigen::Vector3d& point) const;

  struct Op {
    enum Kind : unsigned char { kNumber, kVariable, kNegate, kAdd, kSubtract, kMultiply, kDivide, kPower, kCall1, kCall2 };
    Kind kind;
    int index = 0;  // kVariable: the axis; kCall1, kCall2: the function
    double number = 0;
  };

 private:
  std::vector<Op> program_;
  int stackSize_ = 0;  // the program's deepest stack
};

// What is wrong with a formula and where, as "unknown name 'q' at character 5".
class ExpressionError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace surge
