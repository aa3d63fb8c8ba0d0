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

}  // namespace
}  // namespace extwrench
