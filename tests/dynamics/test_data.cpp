// Data::matches: a workspace is valid only for the Model it was sized and cached from.
#include <gtest/gtest.h>

#include <string>

#include "extwrench/core/error.hpp"
#include "extwrench/dynamics/crba.hpp"
#include "extwrench/dynamics/data.hpp"
#include "extwrench/dynamics/kinematics.hpp"
#include "extwrench/dynamics/momentum.hpp"
#include "extwrench/dynamics/rnea.hpp"
#include "extwrench/model/sample_models.hpp"

namespace extwrench {
namespace {

// The public dynamics functions check their arguments against the model (a q one short read and
// an external wrench on body n + 3 wrote past the workspace's arrays, and returned a plausible τ).
TEST(DynamicsArguments, WrongSizesBodiesAndWorkspacesAreErrorsNamingThem) {
  const Model model = random_chain({.n = 6});
  const Model other = random_chain({.n = 7});
  Data data(model);
  const VectorX z = VectorX::Zero(6), short_q = VectorX::Zero(5);
  const auto message = [](const auto& call) {
    try {
      call();
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_EQ(message([&] { (void)rnea(model, data, short_q, z, z); }),
            "rnea: q has 5 entries, the model has 6 joints");
  EXPECT_EQ(message([&] { (void)rnea(model, data, z, z, short_q); }),
            "rnea: ddq has 5 entries, the model has 6 joints");
  const ExternalWrench far{.body = 9};
  EXPECT_EQ(message([&] {
              (void)rnea(model, data, z, z, z, {&far, 1});
            }),
            "rnea: external wrench body 9 is not a body of the model (0..6)");
  Data other_data(other);
  EXPECT_EQ(message([&] { (void)rnea(model, other_data, z, z, z); }),
            "rnea: data was made for another model (8 bodies, the model has 7)");
  EXPECT_EQ(message([&] { (void)gravity_torques(model, data, short_q); }),
            "gravity_torques: q has 5 entries, the model has 6 joints");
  EXPECT_EQ(message([&] { (void)crba(model, data, short_q); }),
            "crba: q has 5 entries, the model has 6 joints");
  EXPECT_EQ(message([&] { (void)forward_dynamics(model, data, z, z, short_q); }),
            "forward_dynamics: tau has 5 entries, the model has 6 joints");
  EXPECT_EQ(message([&] { (void)coriolis_matrix(model, data, z, short_q); }),
            "coriolis_matrix: dq has 5 entries, the model has 6 joints");
  EXPECT_EQ(message([&] { forward_kinematics(model, data, short_q); }),
            "forward_kinematics: q has 5 entries, the model has 6 joints");
  forward_kinematics(model, data, z);
  EXPECT_EQ(message([&] { (void)body_jacobian(model, data, -1); }),
            "body_jacobian: body -1 is not a body of the model (0..6)");
  Matrix6X J(6, 5);
  EXPECT_EQ(message([&] { point_jacobian(model, data, 3, Vector3::Zero(), J); }),
            "point_jacobian: J has 5 columns, the model has 6 joints");
  // A review: these named forward_kinematics, read past the frames, or wrote past the arrays.
  EXPECT_EQ(message([&] { (void)forward_dynamics(model, data, short_q, z, z); }),
            "forward_dynamics: q has 5 entries, the model has 6 joints");
  EXPECT_EQ(message([&] { (void)coriolis_matrix(model, data, short_q, z); }),
            "coriolis_matrix: q has 5 entries, the model has 6 joints");
  const int frames = static_cast<int>(model.frames.size());
  EXPECT_EQ(message([&] { (void)frame_pose(model, data, frames); }),
            "frame_pose: frame " + std::to_string(frames) + " is not a frame of the model (0.." +
                std::to_string(frames - 1) + ")");
  EXPECT_EQ(message([&] { (void)frame_pose(model, data, -1); }).rfind("frame_pose: frame -1 ", 0),
            0u);
  EXPECT_EQ(message([&] { momentum_terms(model, other_data, z, z); }),
            "momentum_terms: data was made for another model (8 bodies, the model has 7)");
  EXPECT_EQ(message([&] { momentum_and_bias_terms(model, data, z, short_q); }),
            "momentum_and_bias_terms: dq has 5 entries, the model has 6 joints");
  // The right sizes pass.
  EXPECT_EQ(message([&] { (void)rnea(model, data, z, z, z); }), "no error");
}

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
