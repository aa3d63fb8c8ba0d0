// Data::matches: a workspace is valid only for the Model it was sized and cached from.
#include <gtest/gtest.h>

#include "extwrench/dynamics/data.hpp"
#include "extwrench/model/sample_models.hpp"

namespace extwrench {
namespace {

TEST(Data, MatchesTheModelItWasBuiltFor) {
  const Model model = random_chain({.n = 6, .tree = true, .prismatic = true});
  EXPECT_TRUE(Data(model).matches(model));
}

TEST(Data, DoesNotMatchAModelOfAnotherSize) {
  const Model six = random_chain({.n = 6});
  const Model seven = random_chain({.n = 7});
  EXPECT_FALSE(Data(six).matches(seven));
  EXPECT_FALSE(Data(seven).matches(six));
}

TEST(Data, DoesNotMatchAModelOfTheSameSizeWithOtherJoints) {
  const Model model = random_chain({.n = 6});
  Model tilted = model;
  tilted.joints[3].axis = -tilted.joints[3].axis;
  EXPECT_FALSE(Data(model).matches(tilted));
  Model moved = model;
  moved.joints[2].placement.rotation = Matrix3::Identity();
  EXPECT_FALSE(Data(model).matches(moved));
  Model prismatic = model;
  prismatic.joints[5].type = JointType::kPrismatic;
  EXPECT_FALSE(Data(model).matches(prismatic));
}

// rnea reads the mass properties Data cached in each joint-aligned frame.
TEST(Data, DoesNotMatchAModelOfTheSameSizeWithOtherInertias) {
  const Model model = random_chain({.n = 6});
  Model heavier = model;
  heavier.bodies[4].inertia.mass *= 1.5;
  EXPECT_FALSE(Data(model).matches(heavier));
  Model shifted = model;
  shifted.bodies[2].inertia.com.x() += 0.01;
  EXPECT_FALSE(Data(model).matches(shifted));
}

}  // namespace
}  // namespace extwrench
