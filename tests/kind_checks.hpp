// Which constraint kinds have a finite-difference check: CheckSpec<Spec> (constraint_check.hpp) registers Spec
// here when it is instantiated, before main runs, so that tests/test_kind_registry.cpp can require one for every
// kind of kinds/registry.hpp whatever order the tests run in.
#pragma once

#include <set>
#include <typeindex>
#include <typeinfo>

namespace phiq::test {

// The kinds some CheckSpec<Spec> is compiled for, in this test executable.
inline std::set<std::type_index>& kinds_with_fd_check() {
  static std::set<std::type_index> kinds;
  return kinds;
}
// Instantiated by CheckSpec<Spec>: its initialisation (before main) records Spec.
template <class Spec>
struct FdCheckOf {
  static inline const bool registered = (kinds_with_fd_check().insert(std::type_index(typeid(Spec))), true);
};

// The kinds that differentiate their own data (DataDifferentiable) some CheckDataDerivative<Spec> is compiled for.
inline std::set<std::type_index>& kinds_with_data_check() {
  static std::set<std::type_index> kinds;
  return kinds;
}
template <class Spec>
struct DataCheckOf {
  static inline const bool registered = (kinds_with_data_check().insert(std::type_index(typeid(Spec))), true);
};

}  // namespace phiq::test
