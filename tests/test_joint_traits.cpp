// The joint traits of the registry's kinds (JointTraits, kinds/kind_support.hpp) against what the scene reader
// accepts: for every kind read as a named spatial joint, `output.joints` accepts it exactly when its traits say it
// measures something (with a column for each measure), a joint driver exactly when they say it drives that measure,
// and a shaft (`rotation_angle`'s `joint: J`) exactly when they say it is one. The joints are made from each kind's
// own documented example (its sides replaced by ground and a body), so a new kind is covered without an edit here.
#include <gtest/gtest.h>

#include <cstdlib>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "phiq/phiq.hpp"
#include "test_support.hpp"

namespace phiq {
namespace joint_traits_scenes {

// The fields `key: value` at the top level of a one-line flow map `- {…}`.
std::vector<std::pair<std::string, std::string>> top_fields(const std::string& entry) {
  std::vector<std::pair<std::string, std::string>> fields;
  const std::size_t open = entry.find('{'), close = entry.rfind('}');
  std::string part;
  int depth = 0;
  auto flush = [&] {
    const std::size_t colon = part.find(':'), first = part.find_first_not_of(' ');
    if (colon != std::string::npos) fields.emplace_back(part.substr(first, colon - first), part.substr(colon + 2));
    part.clear();
  };
  for (std::size_t k = open + 1; k < close; ++k) {
    const char c = entry[k];
    if (c == '{' || c == '[') ++depth;
    if (c == '}' || c == ']') --depth;
    if (c == ',' && depth == 0) {
      flush();
    } else {
      part += c;
    }
  }
  flush();
  return fields;
}

bool is_number(const std::string& s) {
  char* end = nullptr;
  std::strtod(s.c_str(), &end);
  return !s.empty() && *end == '\0';
}

// One spatial joint form of the registry: its kind's name, scene type and traits.
struct JointForm {
  std::string kind, type;
  JointTraits traits;
  std::string example;
};
// Every constraint form of a kind read as a named spatial joint that joins two sides (`between`).
std::vector<JointForm> joint_forms() {
  std::vector<JointForm> forms;
  ConstraintKinds::for_each([&]<class K>() {
    if constexpr (SpatialJointKind<K>)
      for (const SceneForm& f : K::kScene)
        if (std::string_view(f.section) == "constraints" &&
            std::string_view(f.example).find("between:") != std::string_view::npos)
          forms.push_back({K::kKind, f.type, joint_traits<K>(), f.example});
  });
  return forms;
}

// A scene of one body B and the joint J of form `f` between ground and B (about z), then `more` (entries of the
// constraints section, then the other sections). The example's other fields are kept where numbers; a name becomes
// a coordinate of its own (a rotation_angle's angle), and `theta` is one for `more`.
std::string scene_with(const JointForm& f, const std::string& more_constraints, const std::string& sections) {
  std::string entry = "  - {name: J, type: " + f.type +
                      ", between: [{body: ground, axis: [0, 0, 1]}, {body: B, at: [0, 0, 1], axis: [0, 0, 1]}]";
  std::string coordinates = "theta: 0";
  for (const auto& [key, value] : top_fields(f.example)) {
    if (key == "name" || key == "type" || key == "between") continue;
    if (is_number(value)) {
      entry += ", " + key + ": " + value;
    } else {
      entry += ", " + key + ": c_" + key;
      coordinates += ", c_" + key + ": 0";
    }
  }
  return "phiq: 1\ndimension: 3\ncoordinates: {" + coordinates + "}\nbodies:\n  B: {at: [0, 0, 1]}\nconstraints:\n" +
         entry + "}\n" + more_constraints + "time: {start: 0, end: 1, steps: 1}\n" + sections;
}

std::string list_of(bool (*select)(const JointTraits&)) { return joint_type_list(select); }

TEST(JointTraits, OutputJointsAcceptEveryJointThatMeasuresAndNoOther) {
  int accepted = 0, refused = 0;
  for (const JointForm& f : joint_forms()) {
    SCOPED_TRACE(f.kind + " (" + f.type + ")");
    const std::string text = scene_with(f, "", "output: {joints: [J]}\n");
    if (f.traits.measures.any()) {
      ++accepted;
      const Scene s = parse_scene(text, "joint.yaml");
      std::vector<JointMeasure> expected;
      if (f.traits.measures.angle) expected.push_back(JointMeasure::kAngle);
      if (f.traits.measures.distance) expected.push_back(JointMeasure::kDistance);
      ASSERT_EQ(s.sweep.joints.size(), expected.size());
      for (std::size_t k = 0; k < expected.size(); ++k) {
        EXPECT_EQ(s.sweep.joints[k].name, "J");
        EXPECT_EQ(s.sweep.joints[k].measure, expected[k]);
      }
    } else {
      ++refused;
      EXPECT_HAS(test::scene_error(text),
                 "output.joints[0]: joint 'J' is a " + f.type + " joint: outputs measure the angle of a " +
                     list_of([](const JointTraits& t) { return t.measures.angle; }) + " joint, or the distance of a " +
                     list_of([](const JointTraits& t) { return t.measures.distance; }) + " one");
    }
  }
  EXPECT_GT(accepted, 0);
  EXPECT_GT(refused, 0);
}

TEST(JointTraits, JointDriversAcceptWhatTheJointDrivesAndNothingElse) {
  const std::string refusal =
      "drivers measure the angle of a " + list_of([](const JointTraits& t) { return t.drives.angle; }) +
      " joint, or the distance of a " + list_of([](const JointTraits& t) { return t.drives.distance; }) + " one";
  int driven = 0;
  for (const JointForm& f : joint_forms()) {
    SCOPED_TRACE(f.kind + " (" + f.type + ")");
    auto with_driver = [&](const std::string& measure) {
      return scene_with(f, "", "drivers:\n  - {joint: J" + measure + ", law: {type: linear, initial: 0, rate: 1}}\n");
    };
    for (const auto& [measure, allowed] :
         {std::pair{std::string("angle"), f.traits.drives.angle}, {"distance", f.traits.drives.distance}}) {
      const std::string text = with_driver(", measure: " + measure);
      if (allowed) {
        ++driven;
        EXPECT_NO_THROW(parse_scene(text, "joint.yaml")) << measure;
      } else {
        EXPECT_HAS(test::scene_error(text), "joint 'J' is a " + f.type + " joint: " + refusal);
      }
    }
    // without `measure`: the one it drives, or a request for it when it drives both
    const std::string text = with_driver("");
    if (f.traits.drives.angle != f.traits.drives.distance) {
      EXPECT_NO_THROW(parse_scene(text, "joint.yaml"));
    } else if (f.traits.drives.angle) {
      EXPECT_HAS(test::scene_error(text),
                 "a " + f.type + " joint's driver needs 'measure: angle' or 'measure: distance'");
    } else {
      EXPECT_HAS(test::scene_error(text), refusal);
    }
  }
  EXPECT_GT(driven, 0);
}

TEST(JointTraits, ShaftsAreTheJointsThatTurnAboutTheirAxis) {
  int shafts = 0;
  for (const JointForm& f : joint_forms()) {
    SCOPED_TRACE(f.kind + " (" + f.type + ")");
    const std::string text = scene_with(f, "  - {name: turn, type: rotation_angle, joint: J, angle: theta}\n", "");
    if (f.traits.shaft) {
      ++shafts;
      EXPECT_NO_THROW(parse_scene(text, "joint.yaml"));
    } else {
      EXPECT_HAS(test::scene_error(text), "joint 'J' is a " + f.type + " joint: a shaft turns in a " +
                                              list_of([](const JointTraits& t) { return t.shaft; }) + " joint");
    }
  }
  EXPECT_GT(shafts, 0);
}

}  // namespace joint_traits_scenes
}  // namespace phiq
