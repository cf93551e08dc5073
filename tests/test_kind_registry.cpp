// The registry of constraint kinds (kinds/registry.hpp) is the one list every part of phiq iterates over: these
// tests fail when a registered kind lacks what each part needs — a finite-difference check of its derivatives, a
// scene example documented in models/README.md, its scene types in the fuzzing dictionary — or when two kinds claim
// the same scene type in the same dimension. (Members a kind must supply are checked at compile time by the
// ConstraintKind concept.)
#include <gtest/gtest.h>

#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <tuple>
#include <typeindex>
#include <vector>

#include "kind_checks.hpp"
#include "phiq/constraint_kinds.hpp"

namespace {

std::string read_file(const std::string& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

struct FormOf {
  std::string kind, section, type, example;
  int dimension;
};
// Every scene form of every registered kind, in registry order.
std::vector<FormOf> all_forms() {
  std::vector<FormOf> forms;
  phiq::ConstraintKinds::for_each([&]<class K>() {
    for (const phiq::SceneForm& f : K::kScene) forms.push_back({K::kKind, f.section, f.type, f.example, f.dimension});
  });
  return forms;
}

}  // namespace

TEST(KindRegistry, EveryKindHasAFiniteDifferenceCheck) {
  const auto& checked = phiq::test::kinds_with_fd_check();
  std::vector<std::string> missing;
  phiq::ConstraintKinds::for_each([&]<class K>() {
    if (!checked.count(std::type_index(typeid(K)))) missing.push_back(K::kKind);
  });
  EXPECT_TRUE(missing.empty()) << "kinds without a CheckSpec test: " << ::testing::PrintToString(missing);
  EXPECT_EQ(phiq::ConstraintKinds::size, 35u);
}

TEST(KindRegistry, EveryKindThatDifferentiatesItsDataHasACheckOfIt) {
  const auto& checked = phiq::test::kinds_with_data_check();
  std::vector<std::string> differentiating, missing;
  phiq::ConstraintKinds::for_each([&]<class K>() {
    if constexpr (phiq::DataDifferentiable<K>) {
      differentiating.push_back(K::kKind);
      if (!checked.count(std::type_index(typeid(K)))) missing.push_back(K::kKind);
    }
  });
  EXPECT_TRUE(missing.empty()) << "kinds without a CheckDataDerivative test: " << ::testing::PrintToString(missing);
  EXPECT_EQ(differentiating,
            (std::vector<std::string>{
                "distance", "pin", "point_on_line", "constant_angle", "angle", "polar", "prismatic", "loop",
                "equation", "coupler", "driver", "point_on_curve", "flat_cam",  // planar
                "distance", "dot", "spherical", "revolute", "prismatic", "cylindrical", "universal", "planar", "rigid",
                "point_on_line", "point_on_plane", "joint_distance_driver", "joint_angle_driver",  // spatial
                "gear", "rack_pinion", "belt", "screw", "spatial_gear", "polar3", "angle3"}));  // transmissions, mixed
}

TEST(KindRegistry, EverySceneExampleIsDocumentedInTheModelsReadme) {
  const std::string readme = read_file(PHIQ_SOURCE_DIR "/models/README.md");
  ASSERT_FALSE(readme.empty());
  for (const FormOf& f : all_forms())
    EXPECT_NE(readme.find(f.example), std::string::npos)
        << "models/README.md lacks the example of kind '" << f.kind << "' (" << f.section << ", " << f.type
        << "): " << f.example;
}

TEST(KindRegistry, EveryConstraintTypeIsInTheFuzzingDictionary) {
  const std::string dict = read_file(PHIQ_SOURCE_DIR "/tests/fuzz/scene.dict");
  ASSERT_FALSE(dict.empty());
  for (const FormOf& f : all_forms()) {
    if (f.section != "constraints") continue;
    EXPECT_NE(dict.find("\"" + f.type + "\""), std::string::npos) << "tests/fuzz/scene.dict lacks " << f.type;
  }
}

// The scene reader hands a constraint to the kind claiming its type (src/scene/read_constraints.cpp): two claims
// would make one of them unreachable.
TEST(KindRegistry, NoTwoKindsClaimOneConstraintTypeInOneDimension) {
  std::map<std::tuple<std::string, std::string, int>, std::string> owner;
  for (const FormOf& f : all_forms())
    for (int d : {2, 3}) {
      if (f.section != "constraints") continue;
      if (f.dimension != 0 && f.dimension != d) continue;
      auto [it, fresh] = owner.try_emplace({f.section, f.type, d}, f.kind);
      EXPECT_TRUE(fresh) << f.section << " type '" << f.type << "' in dimension " << d << ": kinds '" << it->second
                         << "' and '" << f.kind << "'";
    }
}
