// Natural points' reactions refused rather than written wrong (phiq/natural_joints.hpp): a point no two bodies
// share, a torsional spring whose angle reads the points, and the mass of or loads on a part of expressions that
// moves with the points but is none of their bodies, each by name; what is taken instead alongside.
#include <gtest/gtest.h>

#include <string>

#include "natural_four_bar_text.hpp"
#include "phiq/phiq.hpp"
#include "test_support.hpp"

namespace phiq {
namespace {

TEST(NaturalReactions, APointNoTwoBodiesShareIsRefusedByName) {
  std::string text = natural_reactions_scene("seed/fourbar_natural.yaml");
  text += "parts:\n" + natural_reactions_part("crank", 0, 0.2, "frame: {origin: O, x: A}, ") +
          natural_reactions_part("coupler", 1, 0.6, "frame: {origin: A, x: B}, ");
  EXPECT_EQ(parse_scene(text + "output: {efforts: all, reactions: [A, O]}\n", "n.yaml").sweep.efforts.reactions.size(),
            2u);
  try {
    (void)parse_scene(text + "output: {efforts: all, reactions: [B]}\n", "n.yaml");
    ADD_FAILURE() << "B is on the coupler alone (no rocker part) and moves in x and y: no joint";
  } catch (const std::exception& e) {  // SceneError
    EXPECT_NE(std::string(e.what()).find("point 'B' is no joint"), std::string::npos) << e.what();
  }
}

// A torsional spring whose angle reads the natural points cannot be divided among a point's bodies: their reactions
// are refused with one (the efforts are not); one on a coordinate of its own is its constraint's (tested above).
TEST(NaturalReactions, ATorsionalSpringOnThePointsWithANaturalPointsReactionIsRefused) {
  std::string text = natural_reactions_scene("seed/fourbar_natural.yaml");
  text += "parts:\n" + natural_reactions_part("crank", 0, 0.2, "frame: {origin: O, x: A}, ") +
          natural_reactions_part("coupler", 1, 0.6, "frame: {origin: A, x: B}, ") +
          "loads:\n  torsional_springs: [{name: return, angle: \"atan2(yA, xA)\", stiffness: 2}]\n";
  EXPECT_HAS(test::scene_error(text + "output: {efforts: all, reactions: [A, O]}\n"),
             "output.reactions: the reaction at natural point 'A' would hold torsional spring 'return''s moment: its "
             "angle reads the points");
  EXPECT_EQ(parse_scene(text + "output: {efforts: all}\n", "n.yaml").sweep.efforts.constraints.size(), 1u);
  EXPECT_EQ(parse_scene(test::replace_first(text, "angle: \"atan2(yA, xA)\"", "coordinate: theta2") +
                            "output: {efforts: all, reactions: [A, O]}\n",
                        "n.yaml")
                .sweep.efforts.reactions.size(),
            2u);
}

// A part on a frame of expressions that reads the points moves with them but is none of their bodies: its mass and
// the loads on it would sit in the points' reactions, and are refused there by name; the same part on a frame of
// points is the coupler's second part and is taken. A part that reads no point (the crank's angle coordinate θ2,
// which its segment_angle owns) is no such part.
TEST(NaturalReactions, LoadsOnAPartThatMovesWithThePointsButIsNoBodyAreRefused) {
  std::string text = natural_reactions_scene("seed/fourbar_natural.yaml");
  text += "parts:\n" + natural_reactions_part("crank", 0, 0.2, "frame: {origin: O, x: A}, ") +
          natural_reactions_part("coupler", 1, 0.6, "frame: {origin: A, x: B}, ") +
          "  lamp: {frame: {at: [xB, yB], angle: \"atan2(yB - yA, xB - xA)\"}}\n";
  const std::string reactions = "output: {efforts: all, reactions: [A, O]}\n";
  const std::string force = "loads:\n  forces: [{name: wind, part: lamp, at: [0.1, 0], force: [1, 0]}]\n";
  const std::string expected = "output.reactions: the reaction at natural point 'A' would hold ";
  const std::string why = ": part 'lamp' moves with the points but is none of their bodies (give it a frame of points)";
  EXPECT_HAS(test::scene_error(text + force + reactions), expected + "force 'wind'" + why);
  EXPECT_HAS(test::scene_error(text + "loads:\n  torques: [{name: twist, part: lamp, torque: 2}]\n" + reactions),
             expected + "torque 'twist'" + why);
  EXPECT_HAS(test::scene_error(text +
                               "loads:\n  springs: [{name: cord, between: [{part: lamp, at: [0, 0]}, {point: [0, 2]}], "
                               "stiffness: 5, free_length: 0.5}]\n" +
                               reactions),
             expected + "spring 'cord''s pull" + why);
  EXPECT_HAS(test::scene_error(test::replace_first(text, "angle: \"atan2(yB - yA, xB - xA)\"}",
                                                   "angle: \"atan2(yB - yA, xB - xA)\"}, mass: 0.5, "
                                                   "center_of_mass: [0, 0], inertia: 0.01") +
                               reactions),
             expected + "the weight and inertia of part 'lamp'" + why);
  // the efforts alone take them; so do the reactions with the lamp on a frame of points, or read off θ2 alone
  EXPECT_EQ(parse_scene(text + force + "output: {efforts: all}\n", "n.yaml").sweep.efforts.constraints.size(), 1u);
  const std::string on_points = "lamp: {frame: {origin: A, x: B}}";
  EXPECT_EQ(parse_scene(test::replace_first(text, "lamp: {frame: {at: [xB, yB], angle: \"atan2(yB - yA, xB - xA)\"}}",
                                            on_points) +
                            force + reactions,
                        "n.yaml")
                .sweep.efforts.reactions.size(),
            2u);
  EXPECT_EQ(parse_scene(test::replace_first(text, "at: [xB, yB], angle: \"atan2(yB - yA, xB - xA)\"",
                                            "at: [\"cos(theta2)\", \"sin(theta2)\"], angle: theta2") +
                            force + reactions,
                        "n.yaml")
                .sweep.efforts.reactions.size(),
            2u);
}

}  // namespace
}  // namespace phiq
