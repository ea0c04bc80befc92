#include "core/expression.h"

#include <cctype>
#include <cmath>
#include <cstdlib>

namespace surge {
namespace {

using Function1 = double (*)(double);
using Function2 = double (*)(double, double);

struct Named1 {
  const char* name;
  Function1 f;
};
struct Named2 {
  const char* name;
  Function2 f;
};

const Named1 kFunctions1[] = {
    {"sin", [](double a) { return std::sin(a); }},   {"cos", [](double a) { return std::cos(a); }},
    {"tan", [](double a) { return std::tan(a); }},   {"asin", [](double a) { return std::asin(a); }},
    {"acos", [](double a) { return std::acos(a); }}, {"atan", [](double a) { return std::atan(a); }},
    {"sinh", [](double a) { return std::sinh(a); }}, {"cosh", [](double a) { return std::cosh(a); }},
    {"tanh", [](double a) { return std::tanh(a); }}, {"exp", [](double a) { return std::exp(a); }},
    {"log", [](double a) { return std::log(a); }},   {"sqrt", [](double a) { return std::sqrt(a); }},
    {"abs", [](double a) { return std::abs(a); }},   {"floor", [](double a) { return std::floor(a); }},
};
const Named2 kFunctions2[] = {
    {"atan2", [](double a, double b) { return std::atan2(a, b); }},
    {"pow", [](double a, double b) { return std::pow(a, b); }},
    {"min", [](double a, double b) { return std::min(a, b); }},
    {"max", [](double a, double b) { return std::max(a, b); }},
};

// Recursive descent, one level per precedence:
//   sum := product (('+' | '-') product)*      product := unary (('*' | '/') unary)*
//   unary := ('-' | '+') unary | power          power := atom ('^' unary)?
//   atom := number | x | y | z | pi | name '(' sum (',' sum)? ')' | '(' sum ')'
class Parser {
 public:
  Parser(const std::string& text, std::vector<Expression::Op>& program) : text_(text), program_(program) {}

  void parse() {
    skipSpace();
    if (at_ == text_.size()) fail("is empty");
    sum();
    if (at_ != text_.size()) fail("unexpected '" + std::string(1, text_[at_]) + "'");
  }

 private:
  [[noreturn]] void fail(const std::string& what) const {
    throw ExpressionError(what + (at_ < text_.size() ? " at character " + std::to_string(at_ + 1) : " at the end"));
  }
  void skipSpace() {
    while (at_ < text_.size() && std::isspace(static_cast<unsigned char>(text_[at_]))) ++at_;
  }
  bool take(char c) {
    if (at_ < text_.size() && text_[at_] == c) {
      ++at_;
      skipSpace();
      return true;
    }
    return false;
  }
  void emit(Expression::Op::Kind kind, int index = 0, double number = 0) { program_.push_back({kind, index, number}); }

  void sum() {
    if (++nesting_ > kMaxNesting) fail("nested too deeply");
    product();
    while (true) {
      if (take('+')) product(), emit(Expression::Op::kAdd);
      else if (take('-')) product(), emit(Expression::Op::kSubtract);
      else break;
    }
    --nesting_;
  }
  void product() {
    unary();
    while (true) {
      if (take('*')) unary(), emit(Expression::Op::kMultiply);
      else if (take('/')) unary(), emit(Expression::Op::kDivide);
      else return;
    }
  }
  void unary() {
    if (++nesting_ > kMaxNesting) fail("nested too deeply");  // a chain of signs or powers recurses here
    if (take('-')) unary(), emit(Expression::Op::kNegate);
    else if (take('+')) unary();
    else power();
    --nesting_;
  }
  void power() {
    atom();
    if (take('^')) unary(), emit(Expression::Op::kPower);  // 2^-1 and 2^3^2 = 2^(3^2)
  }
  void atom() {
    if (at_ == text_.size()) fail("a number, a name or '(' expected");
    const char c = text_[at_];
    if (take('(')) {
      sum();
      if (!take(')')) fail("')' expected");
    } else if (std::isdigit(static_cast<unsigned char>(c)) || c == '.') {
      const char* begin = text_.c_str() + at_;
      char* end = nullptr;
      const double value = std::strtod(begin, &end);
      if (end == begin) fail("a number expected");
      at_ += static_cast<size_t>(end - begin);
      emit(Expression::Op::kNumber, 0, value);
      skipSpace();
    } else if (std::isalpha(static_cast<unsigned char>(c))) {
      const size_t start = at_;
      while (at_ < text_.size() && (std::isalnum(static_cast<unsigned char>(text_[at_])) || text_[at_] == '_')) ++at_;
      const std::string name = text_.substr(start, at_ - start);
      skipSpace();
      named(name, start);
    } else {
      fail("unexpected '" + std::string(1, c) + "'");
    }
  }
  void named(const std::string& name, size_t start) {
    if (name.size() == 1 && name[0] >= 'x' && name[0] <= 'z') return emit(Expression::Op::kVariable, name[0] - 'x');
    if (name == "pi") return emit(Expression::Op::kNumber, 0, M_PI);
    for (size_t f = 0; f < std::size(kFunctions1); ++f)
      if (name == kFunctions1[f].name) return call(1, static_cast<int>(f));
    for (size_t f = 0; f < std::size(kFunctions2); ++f)
      if (name == kFunctions2[f].name) return call(2, static_cast<int>(f));
    at_ = start;
    fail("unknown name '" + name + "' (x, y, z, pi and functions such as sin, exp, sqrt, atan2, min)");
  }
  void call(int arguments, int function) {
    if (!take('(')) fail("'(' expected after a function");
    sum();
    if (arguments == 2 && !take(',')) fail("',' expected (this function takes two arguments)");
    if (arguments == 2) sum();
    if (!take(')')) fail("')' expected");
    emit(arguments == 1 ? Expression::Op::kCall1 : Expression::Op::kCall2, function);
  }

  static constexpr int kMaxNesting = 200;  // the parser's recursion, against a formula that exhausts the stack
  const std::string& text_;
  std::vector<Expression::Op>& program_;
  size_t at_ = 0;
  int nesting_ = 0;
};

}  // namespace

Expression::Expression(const std::string& text) {
  Parser(text, program_).parse();
  int depth = 0;
  for (const Op& op : program_) {
    depth += op.kind == Op::kNumber || op.kind == Op::kVariable ? 1
             : op.kind == Op::kNegate || op.kind == Op::kCall1  ? 0
                                                                : -1;
    stackSize_ = std::max(stackSize_, depth);
  }
}

double Expression::operator()(const Eigen::Vector3d& point) const {
  std::vector<double> stack(static_cast<size_t>(stackSize_));
  int top = 0;
  for (const Op& op : program_) {
    switch (op.kind) {
      case Op::kNumber: stack[top++] = op.number; break;
      case Op::kVariable: stack[top++] = point[op.index]; break;
      case Op::kNegate: stack[top - 1] = -stack[top - 1]; break;
      case Op::kAdd: --top, stack[top - 1] += stack[top]; break;
      case Op::kSubtract: --top, stack[top - 1] -= stack[top]; break;
      case Op::kMultiply: --top, stack[top - 1] *= stack[top]; break;
      case Op::kDivide: --top, stack[top - 1] /= stack[top]; break;
      case Op::kPower: --top, stack[top - 1] = std::pow(stack[top - 1], stack[top]); break;
      case Op::kCall1: stack[top - 1] = kFunctions1[op.index].f(stack[top - 1]); break;
      case Op::kCall2: --top, stack[top - 1] = kFunctions2[op.index].f(stack[top - 1], stack[top]); break;
    }
  }
  return stack[0];
}

}  // namespace surge
