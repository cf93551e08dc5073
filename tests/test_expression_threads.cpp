// Equations compiled on several threads at once, as `phiq batch` and `phiq tolerance` read scenes (a scene per
// thread): the GiNaC work behind CompiledExpression::compile() and along_constants() is serialised
// (compiled_expression.cpp), since GiNaC shares reference-counted numbers between all its expressions. Built with
// ThreadSanitizer, which fails the test (exit code 66) on any race, and compared with the same texts compiled on
// one thread, which catches the corruption a race leaves where TSan is not there to see it.
#include <gtest/gtest.h>

#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "phiq/expression.hpp"

namespace {

using phiq::CompiledExpression;
using phiq::NameBinding;

// x, y coordinates 0 and 1, t, and the constant L (the parameter whose rate along_constants() takes).
phiq::NameResolver resolver(double length) {
  return [length](const std::string& n) -> std::optional<NameBinding> {
    if (n == "x") return NameBinding{NameBinding::Kind::kCoordinate, 0, 0.0};
    if (n == "y") return NameBinding{NameBinding::Kind::kCoordinate, 1, 0.0};
    if (n == "t") return NameBinding{NameBinding::Kind::kTime, -1, 0.0};
    if (n == "L") return NameBinding{NameBinding::Kind::kConstant, -1, length};
    return std::nullopt;
  };
}

const std::vector<std::string> kTexts = {
    "x^2 + y^2 - L^2",
    "L*cos(x) + sqrt(L^2 - (L*sin(x))^2) - y",
    "atan2(y, x) - 2*t + L/3",
    "exp(-x*y) * sin(L*t) + x^3/L",
};

// Everything one text compiles to: g's tapes and those of its rate along L.
std::string compiled(const std::string& text, double length) {
  const auto g = CompiledExpression::compile(text, resolver(length));
  const auto rate = g->along_constants({1.0});
  return g->listing() + "rate:\n" + (rate ? rate->listing() : std::string("none"));
}

TEST(ExpressionThreads, CompilesOnSeveralThreadsAsOnOne) {
  std::vector<std::string> expected;
  for (const std::string& text : kTexts) expected.push_back(compiled(text, 1.5));

  constexpr int kThreads = 4, kRounds = 25;
  std::vector<std::vector<std::string>> seen(kThreads);
  std::vector<std::thread> threads;
  for (int w = 0; w < kThreads; ++w)
    threads.emplace_back([&, w] {
      for (int r = 0; r < kRounds; ++r)
        for (const std::string& text : kTexts) seen[static_cast<std::size_t>(w)].push_back(compiled(text, 1.5));
    });
  for (std::thread& th : threads) th.join();

  for (int w = 0; w < kThreads; ++w) {
    ASSERT_EQ(seen[static_cast<std::size_t>(w)].size(), kTexts.size() * kRounds);
    for (std::size_t k = 0; k < seen[static_cast<std::size_t>(w)].size(); ++k)
      EXPECT_EQ(seen[static_cast<std::size_t>(w)][k], expected[k % kTexts.size()]) << "thread " << w << ", " << k;
  }
  EXPECT_NE(expected[0].find("rate:"), std::string::npos);
  EXPECT_EQ(expected[0].find("rate:\nnone"), std::string::npos);  // L moves every text
}

}  // namespace
