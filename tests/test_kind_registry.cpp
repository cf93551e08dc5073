// The registry of constraint kinds (kinds/registry.hpp) is the one list every part of phiq iterates over: these
// tests fail when a registered kind lacks what each part needs — a finite-difference check of its derivatives, a
// scene example documented in models/README.md, its scene types in the fuzzing dictionary — when two kinds claim
// the same scene type in the same dimension, or when the documentation names a type or a list of joint types the
// registry does not have. Every expected set is derived from the registry (and the checks the tests compile), none
// written here. (Members a kind must supply are checked at compile time by the ConstraintKind concept.)
#include <gtest/gtest.h>

#include <cctype>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <string_view>
#include <tuple>
#include <type_traits>
#include <typeindex>
#include <utility>
#include <vector>

#include "kind_checks.hpp"
#include "phiq/constraint_kinds.hpp"
#include "phiq/model.hpp"
#include "test_support.hpp"

namespace {

// The kinds of the registry, by type, and their names.
std::map<std::type_index, std::string> kinds_by_type() {
  std::map<std::type_index, std::string> kinds;
  phiq::ConstraintKinds::for_each([&]<class K>() { kinds.emplace(std::type_index(typeid(K)), K::kKind); });
  return kinds;
}
// The names of the kinds in `kinds` that `checked` lacks, and of the types in `checked` no kind of `kinds` is.
std::pair<std::vector<std::string>, std::vector<std::string>> missing_and_stray_kinds(
    const std::map<std::type_index, std::string>& kinds, const std::set<std::type_index>& checked) {
  std::pair<std::vector<std::string>, std::vector<std::string>> missing_stray;
  for (const auto& [type, name] : kinds)
    if (!checked.count(type)) missing_stray.first.push_back(name);
  for (const std::type_index& type : checked)
    if (!kinds.count(type)) missing_stray.second.push_back(type.name());
  return missing_stray;
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

// The kinds with a CheckSpec test are the registered kinds, both ways: the count of kinds is the registry's.
TEST(KindRegistry, EveryKindHasAFiniteDifferenceCheck) {
  const auto kinds = kinds_by_type();
  ASSERT_EQ(kinds.size(), phiq::ConstraintKinds::size) << "a kind registered twice";
  const auto [missing, stray] = missing_and_stray_kinds(kinds, phiq::test::kinds_with_fd_check());
  EXPECT_TRUE(missing.empty()) << "kinds without a CheckSpec test: " << ::testing::PrintToString(missing);
  EXPECT_TRUE(stray.empty()) << "CheckSpec tests of unregistered kinds: " << ::testing::PrintToString(stray);
}

// The kinds that differentiate their data (DataDifferentiable) are the kinds with a CheckDataDerivative test, both
// ways; and the registry has some (the sensitivities' exact derivatives along the data rest on them).
// ModelBuilder makes each registered kind's block in the file that compiles it (kinds/typed_blocks.hpp), by its
// place in the list: each place gives its own kind's block, and a place past the list is refused.
TEST(KindRegistry, EachPlaceMakesTheBlockOfItsKind) {
  std::size_t places = 0;
  phiq::ConstraintKinds::for_each([&]<class K>() {
    constexpr std::size_t place = phiq::ConstraintKinds::index_of<K>();
    static_assert(std::is_same_v<phiq::ConstraintKinds::at<place>, K>);
    const auto block = phiq::detail::new_registered_block(place);
    ASSERT_NE(dynamic_cast<const phiq::TypedBlock<K>*>(block.get()), nullptr) << K::kKind;
    EXPECT_STREQ(block->kind(), K::kKind);
    EXPECT_EQ(place, places++);
  });
  EXPECT_EQ(places, phiq::ConstraintKinds::size);
  EXPECT_EQ(phiq::ConstraintKinds::index_of<int>(), phiq::ConstraintKinds::size);
  EXPECT_THROW(phiq::detail::new_registered_block(phiq::ConstraintKinds::size), phiq::Error);
}

TEST(KindRegistry, EveryKindThatDifferentiatesItsDataHasACheckOfIt) {
  std::map<std::type_index, std::string> differentiating;
  phiq::ConstraintKinds::for_each([&]<class K>() {
    if constexpr (phiq::DataDifferentiable<K>) differentiating.emplace(std::type_index(typeid(K)), K::kKind);
  });
  EXPECT_FALSE(differentiating.empty());
  const auto [missing, stray] = missing_and_stray_kinds(differentiating, phiq::test::kinds_with_data_check());
  EXPECT_TRUE(missing.empty()) << "kinds without a CheckDataDerivative test: " << ::testing::PrintToString(missing);
  EXPECT_TRUE(stray.empty()) << "CheckDataDerivative tests of kinds not registered as differentiating their data: "
                             << ::testing::PrintToString(stray);
}

TEST(KindRegistry, EverySceneExampleIsDocumentedInTheModelsReadme) {
  const std::string readme = phiq::test::file_text(PHIQ_SOURCE_DIR "/models/README.md");
  ASSERT_FALSE(readme.empty());
  for (const FormOf& f : all_forms())
    EXPECT_NE(readme.find(f.example), std::string::npos) << "models/README.md lacks the example of kind '" << f.kind
                                                         << "' (" << f.section << ", " << f.type << "): " << f.example;
}

TEST(KindRegistry, EveryConstraintTypeIsInTheFuzzingDictionary) {
  const std::string dict = phiq::test::file_text(PHIQ_SOURCE_DIR "/tests/fuzz/scene.dict");
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

namespace {
// The `type` of every scene entry `- {…}` of a text: the field at the top level of the entry's map (a law's type is
// nested in it).
std::set<std::string> readme_entry_types(const std::string& text) {
  std::set<std::string> types;
  std::istringstream lines(text);
  for (std::string line; std::getline(lines, line);) {
    const std::size_t start = line.find_first_not_of(' ');
    if (start == std::string::npos || line.compare(start, 3, "- {") != 0) continue;
    int depth = 0;
    for (std::size_t k = start + 2; k < line.size(); ++k) {
      if (line[k] == '{' || line[k] == '[') {
        ++depth;
      } else if (line[k] == '}' || line[k] == ']') {
        --depth;
      } else if (depth == 1 && (line[k - 1] == '{' || line[k - 1] == ' ') && line.compare(k, 6, "type: ") == 0) {
        const std::size_t end = line.find_first_of(",}", k + 6);
        types.insert(line.substr(k + 6, end - (k + 6)));
      }
    }
  }
  return types;
}
// The elements of `a` that `b` lacks.
std::vector<std::string> readme_set_minus(const std::set<std::string>& a, const std::set<std::string>& b) {
  std::vector<std::string> d;
  for (const std::string& x : a)
    if (!b.count(x)) d.push_back(x);
  return d;
}
// The scene types of the kinds read as named spatial joints (SpatialJointKind), which the joint traits select from.
std::set<std::string> spatial_joint_types() {
  std::set<std::string> types;
  phiq::ConstraintKinds::for_each([&]<class K>() {
    if constexpr (phiq::SpatialJointKind<K>)
      for (const phiq::SceneForm& f : K::kScene)
        if (std::string_view(f.section) == "constraints") types.insert(f.type);
  });
  return types;
}
// The spatial joint types named in `text` from `anchor` to the first `end` after it.
std::set<std::string> joint_types_named(const std::string& text, const std::string& anchor, const std::string& end) {
  const std::size_t from = text.find(anchor);
  EXPECT_NE(from, std::string::npos) << "no '" << anchor << "'";
  if (from == std::string::npos) return {};
  const std::string part = text.substr(from, text.find(end, from + anchor.size()) - from);
  const std::set<std::string> joints = spatial_joint_types();
  std::set<std::string> named;
  std::string word;
  for (const char c : part + ' ') {
    if (std::islower(static_cast<unsigned char>(c)) || std::isdigit(static_cast<unsigned char>(c)) || c == '_') {
      word += c;
    } else {
      if (joints.count(word)) named.insert(word);
      word.clear();
    }
  }
  return named;
}
}  // namespace

// Every constraint type of the registry has an entry `- {…, type: X, …}` in models/README.md, and every such entry's
// type is a registered one.
TEST(KindRegistry, TheModelsReadmeShowsEveryConstraintTypeAndNoOther) {
  std::set<std::string> registered;
  for (const FormOf& f : all_forms())
    if (f.section == "constraints") registered.insert(f.type);
  const std::set<std::string> shown = readme_entry_types(phiq::test::file_text(PHIQ_SOURCE_DIR "/models/README.md"));
  EXPECT_FALSE(registered.empty());
  EXPECT_EQ(readme_set_minus(registered, shown), std::vector<std::string>{}) << "types without an entry";
  EXPECT_EQ(readme_set_minus(shown, registered), std::vector<std::string>{}) << "entries of no registered type";
}

// The documents' lists of the joint types that outputs, drivers and shafts accept are the joint traits' (the scene
// reader's messages are made of joint_type_list()).
TEST(KindRegistry, TheReadmesListTheJointTypesOfTheJointTraits) {
  auto traits_say = [](auto select) {
    std::set<std::string> types;
    for (std::string_view t : phiq::joint_types(select)) types.insert(std::string(t));
    EXPECT_FALSE(types.empty());
    return types;
  };
  const std::set<std::string> measured = traits_say([](const phiq::JointTraits&t) { return t.measures.any(); }),
                              driven = traits_say([](const phiq::JointTraits&t) { return t.drives.any(); }),
                              shafts = traits_say([](const phiq::JointTraits&t) { return t.shaft; });
  const std::string models = phiq::test::file_text(PHIQ_SOURCE_DIR "/models/README.md"),
                    tools = phiq::test::file_text(PHIQ_SOURCE_DIR "/tools/README.md");
  EXPECT_EQ(joint_types_named(models, "| `joints` |", "\n"), measured) << "models/README.md, output: joints";
  EXPECT_EQ(joint_types_named(tools, "per joint J of `output.joints`", "\n"), measured) << "tools/README.md";
  EXPECT_EQ(joint_types_named(models, "| `joint: J`, `measure: angle` or `distance` |", "\n"), driven)
      << "models/README.md, joint drivers";
  EXPECT_EQ(joint_types_named(models, "`shafts: [J1, J2]`", ")"), shafts) << "models/README.md, spatial_gear";
  EXPECT_EQ(joint_types_named(models, "`joint: J` (a named", ")"), shafts) << "models/README.md, rotation_angle";
}
