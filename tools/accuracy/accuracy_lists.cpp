// The lists of `phiq sweep-accuracy`'s options read into the grid's values (--tolerances, --steps-list,
// --predictors, --newton, --linear-solvers), each item checked with a one-line error naming its option.
#include <algorithm>
#include <charconv>
#include <stdexcept>

#include "sweep_accuracy.hpp"

namespace phiq::tools {

namespace {

std::vector<std::string> split(const std::string& list, const char* option) {
  std::vector<std::string> out;
  std::size_t start = 0;
  while (start <= list.size()) {
    const std::size_t end = std::min(list.find(',', start), list.size());
    std::string item = list.substr(start, end - start);
    if (item.empty()) throw std::invalid_argument(std::string(option) + ": empty item in '" + list + "'");
    out.push_back(item);
    start = end + 1;
  }
  return out;
}

}  // namespace

std::vector<double> parse_tolerances(const std::string& list) {
  std::vector<double> out;
  for (const std::string& item : split(list, "--tolerances")) {
    double v = 0;
    auto r = std::from_chars(item.data(), item.data() + item.size(), v);
    if (r.ec != std::errc() || r.ptr != item.data() + item.size() || !(v > 0 && v < 1))
      throw std::invalid_argument("--tolerances: '" + item + "' is not a number between 0 and 1");
    out.push_back(v);
  }
  return out;
}

std::vector<Index> parse_steps(const std::string& list) {
  std::vector<Index> out;
  for (const std::string& item : split(list, "--steps-list")) {
    long long v = 0;
    auto r = std::from_chars(item.data(), item.data() + item.size(), v);
    if (r.ec != std::errc() || r.ptr != item.data() + item.size() || v < 1 || v > 100'000'000)
      throw std::invalid_argument("--steps-list: '" + item + "' is not a step count (1 to 10^8)");
    out.push_back(static_cast<Index>(v));
  }
  return out;
}

std::vector<Predictor> parse_predictors(const std::string& list) {
  std::vector<Predictor> out;
  for (const std::string& item : split(list, "--predictors")) {
    Predictor p{};
    if (!predictor_from_string(item, &p))
      throw std::invalid_argument("--predictors: unknown predictor '" + item + "' (" + predictor_names() + ")");
    out.push_back(p);
  }
  return out;
}

std::vector<JacobianUpdate> parse_newton(const std::string& list) {
  std::vector<JacobianUpdate> out;
  for (const std::string& item : split(list, "--newton")) {
    if (item == "modified")
      out.push_back(JacobianUpdate::kWhenSlow);
    else if (item == "full")
      out.push_back(JacobianUpdate::kEveryIteration);
    else
      throw std::invalid_argument("--newton: '" + item + "' is modified or full");
  }
  return out;
}

std::vector<LinearSolverKind> parse_linear_solvers(const std::string& list) {
  std::vector<LinearSolverKind> out;
  for (const std::string& item : split(list, "--linear-solvers")) {
    if (item == "klu")
      out.push_back(LinearSolverKind::kKlu);
    else if (item == "umfpack")
      out.push_back(LinearSolverKind::kUmfpack);
    else if (item == "dense")
      out.push_back(LinearSolverKind::kDense);
    else
      throw std::invalid_argument("--linear-solvers: '" + item + "' is klu, umfpack or dense");
  }
  return out;
}

}  // namespace phiq::tools
