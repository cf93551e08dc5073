// libFuzzer target: any byte string as an equation's text. CompiledExpression::compile must either compile it or
// throw phiq::Error with a one-line message that quotes the expression; nothing else may escape (a crash, a hang,
// a sanitizer report). What compiles is evaluated once (value, gradient, Φt, γ) at a fixed point: any double,
// NaN included, is a valid answer there, but the evaluation must not crash. The scene fuzzer reaches expressions
// only through YAML, so this target spends its whole budget on the text the symbolic engine sees.
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "phiq/expression.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  auto resolve = [](const std::string& n) -> std::optional<phiq::NameBinding> {
    if (n == "x") return phiq::NameBinding{phiq::NameBinding::Kind::kCoordinate, 0};
    if (n == "y") return phiq::NameBinding{phiq::NameBinding::Kind::kCoordinate, 1};
    if (n == "L") return phiq::NameBinding{phiq::NameBinding::Kind::kConstant, -1, 0.5};
    if (n == "t") return phiq::NameBinding{phiq::NameBinding::Kind::kTime};
    return std::nullopt;
  };
  std::shared_ptr<const phiq::CompiledExpression> e;
  try {
    e = phiq::CompiledExpression::compile(text, resolve);
  } catch (const phiq::Error& err) {
    const std::string m = err.what();
    if (m.empty() || m.find('\n') != std::string::npos) {
      std::fprintf(stderr, "fuzz_expression: error is not one line: [%s]\n", m.c_str());
      std::abort();
    }
    return 0;
  }
  const double q[2] = {0.3, -0.7}, qd[2] = {1.1, 0.4};
  std::vector<double> g(e->coordinates().size());
  (void)e->value(q, 0.25);
  e->gradient(q, 0.25, g.data());
  (void)e->partial_t(q, 0.25);
  (void)e->gamma(q, qd, 0.25);
  return 0;
}
