// PHCpack (`phc -b`, Debian's phcpack) as the peer of phiq's homotopy in the modes tests (test_modes_phc.cpp,
// test_modes_scenes.cpp): a system solved by phc, and its solutions compared with phiq's endpoints.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <complex>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include <unistd.h>

#include "phiq/modes.hpp"

namespace phiq::modes_phc {

inline bool phc_installed() { return std::system("command -v phc > /dev/null 2>&1") == 0; }

// One solution as phc writes it: the values of x1 … xn, and whether phc calls it real.
struct PhcSolution {
  std::vector<std::complex<double>> x;
  bool real = false;
  bool regular = false;
  bool singular = false;  // a solution (not "no solution") whose rco is at most 1e-10
};

// Runs `phc -b` on the system's text and reads the solutions of the last "THE SOLUTIONS" section (after its
// root refinement).
inline std::vector<PhcSolution> phc_solve(const PolynomialSystem& system) {
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("phiq_modes_phc_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const std::string in = (dir / "in.phc").string(), out = (dir / "out.phc").string();
  std::ofstream(in) << phc_input_text(system);
  const std::string command = "cd '" + dir.string() + "' && phc -b in.phc out.phc < /dev/null > /dev/null 2>&1";
  EXPECT_EQ(std::system(command.c_str()), 0) << command;
  std::ifstream file(out);
  std::stringstream all;
  all << file.rdbuf();
  const std::string text = all.str();
  std::filesystem::remove_all(dir);
  const std::size_t at = text.rfind("THE SOLUTIONS");
  std::vector<PhcSolution> solutions;
  if (at == std::string::npos) return solutions;
  std::istringstream lines(text.substr(at));
  std::string line;
  PhcSolution current;
  bool reading = false;
  while (std::getline(lines, line)) {
    if (line.find("the solution for t") != std::string::npos) {
      reading = true;
      current = PhcSolution{};
      continue;
    }
    if (!reading) continue;
    if (line.rfind("==", 0) == 0) {
      // phc's own words ("real regular") are not written for every system (not for one unknown): judged here from
      // its numbers, as phiq judges its own (the inverse condition estimate rco, the imaginary parts)
      const std::size_t rco = line.find("rco :");
      // (a path phc did not end on a solution says "no solution", whatever its rco)
      const bool solution = rco != std::string::npos && line.find("no solution") == std::string::npos;
      current.regular = solution && std::stod(line.substr(rco + 5)) > 1e-10;
      current.singular = solution && !current.regular;
      double size = 0.0, imag = 0.0;
      for (const auto& v : current.x) size = std::max(size, std::abs(v)), imag = std::max(imag, std::abs(v.imag()));
      current.real = imag <= 1e-8 * (1.0 + size);
      solutions.push_back(current);
      reading = false;
      continue;
    }
    // " xK :  re  im": phc numbers the unknowns in the order it first reads them, not by name
    std::istringstream fields(line);
    std::string name, colon;
    double re = 0.0, im = 0.0;
    if (fields >> name >> colon >> re >> im && name.size() > 1 && name[0] == 'x') {
      const std::size_t k = static_cast<std::size_t>(std::stoi(name.substr(1)) - 1);
      if (current.x.size() <= k) current.x.resize(k + 1);
      current.x[k] = {re, im};
    }
  }
  return solutions;
}

// phc's real solutions: the regular ones, and the singular ones counted once per point (phc lists a multiple root
// once for each path that reached it). (phc -b's polyhedral homotopy counts the roots with no coordinate zero, and
// a mechanism's system in displacements from its placement has roots with some: the system goes to phc shifted by
// x = y + 0.3 + 0.1 v.)
struct PhcRealCounts {
  int regular = 0;
  int singular = 0;
};

// The system in y = x − shift: Π (y_v + shift_v)^{e_v} expanded binomially.
inline PolynomialSystem phc_shifted(const PolynomialSystem& system, const std::vector<double>& shift) {
  PolynomialSystem out{system.variables, system.names, {}};
  for (const Polynomial& p : system.equations) {
    std::map<std::vector<int>, std::complex<double>> sum{};
    for (const PolynomialTerm& t : p.terms) {
      std::map<std::vector<int>, std::complex<double>> expanded{
          {std::vector<int>(t.exponent.size(), 0), t.coefficient}};
      for (std::size_t v = 0; v < t.exponent.size(); ++v) {
        std::map<std::vector<int>, std::complex<double>> next;
        for (const auto& [e, c] : expanded) {
          double binomial = 1.0;
          for (int k = 0; k <= t.exponent[v]; ++k) {  // C(n, k) y^k shift^(n − k)
            std::vector<int> f = e;
            f[v] = k;
            next[f] += c * binomial * std::pow(shift[v], t.exponent[v] - k);
            binomial = binomial * (t.exponent[v] - k) / (k + 1);
          }
        }
        expanded = std::move(next);
      }
      for (const auto& [e, c] : expanded) sum[e] += c;
    }
    Polynomial q;
    for (const auto& [e, c] : sum) q.terms.push_back({c, e});
    out.equations.push_back(std::move(q));
  }
  return out;
}

inline PhcRealCounts phc_real_counts(const PolynomialSystem& system) {
  std::vector<double> shift;
  for (int v = 0; v < system.variables; ++v) shift.push_back(0.3 + 0.1 * v);
  // the real solutions in clusters (1e-5 apart at most): a point several paths reach is a multiple root, singular
  // even where phc's rco for one of its paths is above its 1e-10 (as phiq judges its own endpoints)
  struct Cluster {
    std::vector<std::complex<double>> x;
    int paths = 0;
    bool singular = false;
  };
  std::vector<Cluster> clusters;
  for (const PhcSolution& s : phc_solve(phc_shifted(system, shift))) {
    double size = 0.0, imag = 0.0;
    for (const auto& v : s.x) size = std::max(size, std::abs(v)), imag = std::max(imag, std::abs(v.imag()));
    if (!(s.regular || s.singular) || !(imag <= 1e-5 * (1.0 + size))) continue;
    auto same = std::find_if(clusters.begin(), clusters.end(), [&](const Cluster& c) {
      double d = 0.0;
      for (std::size_t v = 0; v < c.x.size() && v < s.x.size(); ++v) d = std::max(d, std::abs(c.x[v] - s.x[v]));
      return c.x.size() == s.x.size() && d <= 1e-5 * (1.0 + size);
    });
    if (same == clusters.end()) same = clusters.insert(clusters.end(), Cluster{s.x});
    ++same->paths;
    same->singular = same->singular || s.singular;
  }
  PhcRealCounts counts;
  for (const Cluster& c : clusters) (c.singular || c.paths > 1 ? counts.singular : counts.regular) += 1;
  return counts;
}

// phc's solutions against phiq's endpoints: regular finite counts, real counts, and every real solution of one
// found by the other (phc's variables are x1 … xn in the system's order).
inline void modes_expect_same_as_phc(const PolynomialSystem& system, const ModesSummary& ours) {
  const std::vector<PhcSolution> theirs = phc_solve(system);
  int regular = 0, real = 0;
  for (const PhcSolution& s : theirs) regular += s.regular, real += s.regular && s.real;
  EXPECT_EQ(ours.real + ours.complex, regular);
  EXPECT_EQ(ours.real, real);
  for (const Endpoint& e : ours.endpoints) {
    if (e.kind != EndpointKind::kReal) continue;
    bool found = false;
    for (const PhcSolution& s : theirs) {
      if (!s.real || static_cast<Eigen::Index>(s.x.size()) != e.x.size()) continue;
      double d = 0.0;
      for (Eigen::Index v = 0; v < e.x.size(); ++v)
        d = std::max(d, std::abs(s.x[static_cast<std::size_t>(v)] - e.x(v)));
      found = found || d < 1e-8;
    }
    EXPECT_TRUE(found) << "a real solution of phiq's that phc did not find";
  }
}

}  // namespace phiq::modes_phc
