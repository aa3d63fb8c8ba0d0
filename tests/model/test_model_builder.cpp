#include <gtest/gtest.h>

#include <cmath>
#include <functional>

#include "extwrench/core/error.hpp"
#include "extwrench/model/model_builder.hpp"
#include "support/random.hpp"

namespace extwrench {
namespace {

constexpr double kTol = 1e-12;

// Mass properties of a cloud of point masses, computed from the definition (independent of
// Inertia::operator+ and the parallel-axis code).
Inertia cloud_inertia(const std::vector<std::pair<double, Vector3>>& points) {
  Inertia in;
  for (const auto& [m, p] : points) {
    in.mass += m;
    in.com += m * p;
  }
  in.com /= in.mass;
  for (const auto& [m, p] : points) {
    const Vector3 d = p - in.com;
    in.inertia_com += m * (d.squaredNorm() * Matrix3::Identity() - d * d.transpose());
  }
  return in;
}

std::vector<std::pair<double, Vector3>> random_cloud(test::SeededRng& rng, int n) {
  std::vector<std::pair<double, Vector3>> pts;
  for (int i = 0; i < n; ++i)
    pts.emplace_back(rng.uniform(0.1, 2.0), rng.uniform_vector3(-0.5, 0.5));
  return pts;
}

void expect_inertia_near(const Inertia& a, const Inertia& b, double tol) {
  EXPECT_NEAR(a.mass, b.mass, tol);
  EXPECT_LE((a.com - b.com).norm(), tol);
  EXPECT_LE((a.inertia_com - b.inertia_com).cwiseAbs().maxCoeff(), tol);
}

Inertia box_inertia(double m, const Vector3& com, double sx, double sy, double sz) {
  Inertia in;
  in.mass = m;
  in.com = com;
  in.inertia_com.diagonal() << m / 12 * (sy * sy + sz * sz), m / 12 * (sx * sx + sz * sz),
      m / 12 * (sx * sx + sy * sy);
  return in;
}

LinkSpec link(const std::string& name, const Inertia& in) {
  return LinkSpec{name, in, "test.urdf:" + name, ""};
}

JointSpec joint(const std::string& name, JointSpecType type, const std::string& parent,
                const std::string& child, const Pose& origin = Pose::identity(),
                const Vector3& axis = Vector3::UnitZ()) {
  JointSpec j;
  j.name = name;
  j.type = type;
  j.parent = parent;
  j.child = child;
  j.origin = origin;
  j.axis = axis;
  j.source = "test.urdf:" + name;
  return j;
}

const Inertia kBox = box_inertia(1.0, Vector3(0.01, 0.02, 0.1), 0.1, 0.1, 0.3);

std::string build_error(const ModelBuilder& b) {
  try {
    (void)b.build();
  } catch (const Error& e) {
    return e.what();
  }
  return "(no error)";
}

TEST(Inertia, SumOfTwoCloudsEqualsTheInertiaOfTheUnion) {
  test::SeededRng rng(1);
  const auto a = random_cloud(rng, 5);
  const auto b = random_cloud(rng, 7);
  auto all = a;
  all.insert(all.end(), b.begin(), b.end());
  expect_inertia_near(cloud_inertia(a) + cloud_inertia(b), cloud_inertia(all), 1e-12);
}

TEST(Inertia, TransformedEqualsTheInertiaOfTheTransformedCloud) {
  test::SeededRng rng(2);
  const auto pts = random_cloud(rng, 6);
  const Pose X = Pose::from_xyz_rpy(rng.uniform_vector3(-1, 1), rng.uniform_vector3(-3, 3));
  auto moved = pts;
  for (auto& [m, p] : moved) p = X.act(p);
  expect_inertia_near(cloud_inertia(pts).transformed(X), cloud_inertia(moved), 1e-12);
}

TEST(Inertia, SumWithAMasslessBodyKeepsTheMassiveOne) {
  Inertia zero;
  expect_inertia_near(kBox + zero, kBox, kTol);
  expect_inertia_near(zero + kBox, kBox, kTol);
}

TEST(ValidateInertia, AcceptsBoxesPointMassesAndThinRods) {
  EXPECT_NO_THROW(validate_inertia(kBox, "box"));
  Inertia point;
  point.mass = 2.0;
  EXPECT_NO_THROW(validate_inertia(point, "point"));
  Inertia
      rod;  // thin rod along z: I_zz = 0, I_xx = I_yy -> triangle inequality holds with equality
  rod.mass = 1.0;
  rod.inertia_com.diagonal() << 1.0 / 12, 1.0 / 12, 0.0;
  EXPECT_NO_THROW(validate_inertia(rod, "rod"));
}

TEST(ValidateInertia, RejectsNonPhysicalMassProperties) {
  struct Case {
    const char* what;
    Inertia in;
    const char* expected;
  };
  Inertia negative = kBox;
  negative.mass = -1.0;
  Inertia nan = kBox;
  nan.com.x() = std::nan("");
  Inertia asym = kBox;
  asym.inertia_com(0, 1) = 0.001;
  Inertia not_psd = kBox;
  not_psd.inertia_com(0, 1) = not_psd.inertia_com(1, 0) = 0.1;
  Inertia triangle = kBox;
  triangle.inertia_com.diagonal() << 0.01, 0.01, 0.05;
  const Case cases[] = {{"negative mass", negative, "mass: must not be negative"},
                        {"nan", nan, "centre of mass: expected finite"},
                        {"asymmetric", asym, "not symmetric"},
                        {"not psd", not_psd, "not positive semi-definite"},
                        {"triangle", triangle, "triangle inequality"}};
  for (const Case& c : cases) {
    try {
      validate_inertia(c.in, "where.urdf:7: link 'x'");
      ADD_FAILURE() << c.what << ": no error";
    } catch (const Error& e) {
      const std::string msg = e.what();
      EXPECT_EQ(msg.rfind("where.urdf:7: link 'x'", 0), 0u) << msg;
      EXPECT_NE(msg.find(c.expected), std::string::npos) << c.what << ": " << msg;
    }
  }
}

TEST(ModelBuilder, SerialChainHasPaperIndexingAndAFramePerLink) {
  ModelBuilder b;
  b.set_name("chain");
  for (int i = 0; i <= 3; ++i) b.add_link(link("l" + std::to_string(i), kBox));
  for (int i = 1; i <= 3; ++i) {
    b.add_joint(joint("j" + std::to_string(i), JointSpecType::kRevolute,
                      "l" + std::to_string(i - 1), "l" + std::to_string(i),
                      Pose::from_xyz_rpy(Vector3(0, 0, 0.3), Vector3::Zero()), Vector3(0, 0, 2.0)));
  }
  const Model m = b.build();
  EXPECT_EQ(m.nq(), 3);
  EXPECT_TRUE(m.is_serial_chain());
  EXPECT_EQ(m.parents[0], -1);
  for (int i = 0; i <= 3; ++i) {
    EXPECT_EQ(m.bodies[static_cast<std::size_t>(i)].name, "l" + std::to_string(i));
    EXPECT_EQ(m.frames[static_cast<std::size_t>(m.frame_index("l" + std::to_string(i)))].body, i);
  }
  EXPECT_EQ(*m.find_joint("j2"), 2);
  EXPECT_TRUE(m.joints[1].axis.isApprox(Vector3::UnitZ(), kTol)) << "axis must be normalized";
  EXPECT_NEAR(m.total_mass(), 4.0, kTol);
  EXPECT_TRUE(m.gravity.isApprox(Vector3(0, 0, -9.81)));
  EXPECT_TRUE(m.is_ancestor(1, 3));
  EXPECT_FALSE(m.is_ancestor(3, 1));
  EXPECT_NO_THROW(validate_model(m));
}

TEST(ModelBuilder, TreeBodiesAreDepthFirstWithParentsBeforeChildren) {
  // Declared out of order: the builder sorts them.
  ModelBuilder b;
  for (const char* n : {"c2", "root", "b1", "c1", "a1", "b2"}) b.add_link(link(n, kBox));
  b.add_joint(joint("jb2", JointSpecType::kRevolute, "b1", "b2"));
  b.add_joint(joint("ja1", JointSpecType::kRevolute, "root", "a1"));
  b.add_joint(
      joint("jb1", JointSpecType::kRevolute, "root", "b1", Pose::identity(), Vector3::UnitX()));
  b.add_joint(
      joint("jc1", JointSpecType::kPrismatic, "a1", "c1", Pose::identity(), Vector3::UnitY()));
  b.add_joint(
      joint("jc2", JointSpecType::kContinuous, "a1", "c2", Pose::identity(), Vector3::UnitX()));
  const Model m = b.build();
  ASSERT_EQ(m.num_bodies(), 6);
  EXPECT_EQ(m.bodies[0].name, "root");
  EXPECT_FALSE(m.is_serial_chain());
  for (int i = 1; i < m.num_bodies(); ++i) {
    EXPECT_LT(m.parents[static_cast<std::size_t>(i)], i);
    EXPECT_EQ(m.bodies[static_cast<std::size_t>(m.parents[static_cast<std::size_t>(i)])].name,
              m.joints[static_cast<std::size_t>(i)].name == "jb2"   ? "b1"
              : m.joints[static_cast<std::size_t>(i)].name == "jc1" ? "a1"
              : m.joints[static_cast<std::size_t>(i)].name == "jc2" ? "a1"
                                                                    : "root");
  }
  // Depth first: a subtree is contiguous (a1's children directly follow it).
  const int a1 = m.body_index("a1");
  EXPECT_EQ(m.parents[static_cast<std::size_t>(a1 + 1)], a1);
  EXPECT_EQ(m.parents[static_cast<std::size_t>(a1 + 2)], a1);
  const int c2 = m.body_index("c2");
  EXPECT_EQ(m.joints[static_cast<std::size_t>(c2)].type, JointType::kRevolute);
  EXPECT_TRUE(std::isinf(m.joints[static_cast<std::size_t>(c2)].upper))
      << "continuous joints have no limits";
  EXPECT_EQ(m.joints[static_cast<std::size_t>(m.body_index("c1"))].type, JointType::kPrismatic);
}

TEST(ModelBuilder, FixedJointMergeEqualsManualCombination) {
  const Pose X_ab = Pose::from_xyz_rpy(Vector3(0.1, -0.2, 0.3), Vector3(0.3, -0.4, 1.2));
  const Pose X_bc = Pose::from_xyz_rpy(Vector3(0.0, 0.05, 0.2), Vector3(-1.0, 0.2, 0.1));
  const Inertia ia = box_inertia(2.0, Vector3(0.0, 0.0, 0.1), 0.1, 0.2, 0.3);
  const Inertia ib = box_inertia(0.5, Vector3(0.02, 0.0, 0.0), 0.05, 0.05, 0.1);
  const Inertia ic = box_inertia(0.3, Vector3(0.0, 0.01, 0.02), 0.03, 0.04, 0.05);
  ModelBuilder b;
  b.add_link(link("base", kBox));
  b.add_link(link("a", ia));
  b.add_link(link("b", ib));
  b.add_link(link("c", ic));
  b.add_link(link("tip", kBox));
  b.add_joint(joint("j1", JointSpecType::kRevolute, "base", "a"));
  b.add_joint(joint("fab", JointSpecType::kFixed, "a", "b", X_ab));
  b.add_joint(joint("fbc", JointSpecType::kFixed, "b", "c", X_bc));
  const Pose X_ct = Pose::from_xyz_rpy(Vector3(0, 0, 0.1), Vector3(0.5, 0, 0));
  b.add_joint(joint("j2", JointSpecType::kRevolute, "c", "tip", X_ct, Vector3::UnitY()));
  const Model m = b.build();
  ASSERT_EQ(m.num_bodies(), 3);
  const Inertia manual = ia + ib.transformed(X_ab) + ic.transformed(X_ab * X_bc);
  expect_inertia_near(m.bodies[1].inertia, manual, 1e-12);
  // Merged links stay addressable as frames of body 1.
  const Frame& fc = m.frames[static_cast<std::size_t>(m.frame_index("c"))];
  EXPECT_EQ(fc.body, 1);
  EXPECT_TRUE(fc.placement.is_approx(X_ab * X_bc, 1e-12));
  EXPECT_EQ(m.body_index("b"), 1);
  // The joint after the merged links is placed from the body frame.
  EXPECT_TRUE(m.joints[2].placement.is_approx(X_ab * X_bc * X_ct, 1e-12));
}

TEST(ModelBuilder, ExtraFramesAndGravityAreKept) {
  ModelBuilder b;
  b.add_link(link("base", kBox));
  b.add_link(link("a", kBox));
  b.add_joint(joint("j1", JointSpecType::kRevolute, "base", "a"));
  const Pose X = Pose::from_xyz_rpy(Vector3(0, 0, 0.1), Vector3::Zero());
  b.add_frame(FrameSpec{"tool", "a", X, "test:tool"});
  b.set_gravity(Vector3(9.81, 0, 0));
  const Model m = b.build();
  EXPECT_EQ(m.frames[static_cast<std::size_t>(m.frame_index("tool"))].body, 1);
  EXPECT_TRUE(m.gravity.isApprox(Vector3(9.81, 0, 0)));
  EXPECT_THROW((void)m.frame_index("nope"), Error);
  EXPECT_EQ(m.body_index("tool"), 1);
}

TEST(ModelBuilder, MasslessIntermediateLinkIsFineWhenTheMassMatrixStaysDefinite) {
  // A two-axis wrist with a massless link between the axes: M(0) is still positive definite.
  ModelBuilder b;
  b.add_link(link("base", kBox));
  b.add_link(link("mid", Inertia{}));
  b.add_link(link("hand", kBox));
  b.add_joint(joint("j1", JointSpecType::kRevolute, "base", "mid"));
  b.add_joint(
      joint("j2", JointSpecType::kRevolute, "mid", "hand", Pose::identity(), Vector3::UnitY()));
  EXPECT_NO_THROW((void)b.build());
}

TEST(ModelBuilder, MasslessLeafIsRejectedNamingItsJoint) {
  ModelBuilder b;
  b.add_link(link("base", kBox));
  b.add_link(link("a", kBox));
  b.add_link(link("ghost", Inertia{}));
  b.add_joint(joint("j1", JointSpecType::kRevolute, "base", "a"));
  b.add_joint(joint("j2", JointSpecType::kRevolute, "a", "ghost"));
  const std::string msg = build_error(b);
  EXPECT_EQ(msg.rfind("test.urdf:j2: joint 'j2'", 0), 0u) << msg;
  EXPECT_NE(msg.find("not positive definite"), std::string::npos) << msg;
}

TEST(ModelBuilder, MasslessLeafMergedByAFixedJointIsFine) {
  ModelBuilder b;
  b.add_link(link("base", kBox));
  b.add_link(link("a", kBox));
  b.add_link(link("tcp", Inertia{}));
  b.add_joint(joint("j1", JointSpecType::kRevolute, "base", "a"));
  b.add_joint(joint("f", JointSpecType::kFixed, "a", "tcp"));
  const Model m = b.build();
  EXPECT_EQ(m.nq(), 1);
  EXPECT_EQ(m.body_index("tcp"), 1);
}

TEST(ModelBuilder, StructuralErrorsNameTheSourceElementAndField) {
  struct Case {
    const char* what;
    std::function<void(ModelBuilder&)> edit;
    const char* prefix;
    const char* expected;
  };
  const auto base = [](ModelBuilder& b) {
    b.add_link(link("l0", kBox));
    b.add_link(link("l1", kBox));
    b.add_joint(joint("j1", JointSpecType::kRevolute, "l0", "l1"));
  };
  const Case cases[] = {
      {"duplicate link", [](ModelBuilder& b) { b.add_link(link("l1", kBox)); },
       "test.urdf:l1: link 'l1'", "duplicate"},
      {"duplicate joint",
       [](ModelBuilder& b) {
         b.add_link(link("l2", kBox));
         b.add_joint(joint("j1", JointSpecType::kRevolute, "l1", "l2"));
       },
       "test.urdf:j1: joint 'j1'", "duplicate joint name"},
      {"missing parent",
       [](ModelBuilder& b) { b.add_joint(joint("j2", JointSpecType::kRevolute, "nope", "l1")); },
       "test.urdf:j2: joint 'j2'", "parent: no link named 'nope'"},
      {"missing child",
       [](ModelBuilder& b) { b.add_joint(joint("j2", JointSpecType::kRevolute, "l1", "nope")); },
       "test.urdf:j2: joint 'j2'", "child: no link named 'nope'"},
      {"two parents",
       [](ModelBuilder& b) {
         b.add_link(link("l2", kBox));
         b.add_joint(joint("j2", JointSpecType::kRevolute, "l0", "l2"));
         b.add_joint(joint("j3", JointSpecType::kRevolute, "l1", "l2"));
       },
       "test.urdf:j3: joint 'j3'", "already has a parent joint 'j2'"},
      {"two roots", [](ModelBuilder& b) { b.add_link(link("island", kBox)); },
       "test.urdf:island: link 'island'", "more than one root"},
      {"cycle",
       [](ModelBuilder& b) {
         b.add_link(link("x", kBox));
         b.add_link(link("y", kBox));
         b.add_joint(joint("jxy", JointSpecType::kRevolute, "x", "y"));
         b.add_joint(joint("jyx", JointSpecType::kRevolute, "y", "x"));
       },
       "test.urdf:j", "closes a cycle"},
      {"zero axis",
       [](ModelBuilder& b) {
         b.add_link(link("l2", kBox));
         b.add_joint(
             joint("j2", JointSpecType::kRevolute, "l1", "l2", Pose::identity(), Vector3::Zero()));
       },
       "test.urdf:j2: joint 'j2'", "axis: must not be zero"},
      {"limits",
       [](ModelBuilder& b) {
         b.add_link(link("l2", kBox));
         JointSpec j = joint("j2", JointSpecType::kRevolute, "l1", "l2");
         j.lower = 1.0;
         j.upper = -1.0;
         b.add_joint(j);
       },
       "test.urdf:j2: joint 'j2'", "lower 1 > upper -1"},
      {"non-finite origin",
       [](ModelBuilder& b) {
         b.add_link(link("l2", kBox));
         b.add_joint(joint("j2", JointSpecType::kRevolute, "l1", "l2",
                           Pose::from_xyz_rpy(Vector3(std::nan(""), 0, 0), Vector3::Zero())));
       },
       "test.urdf:j2: joint 'j2'", "origin: expected finite"},
      {"bad inertia",
       [](ModelBuilder& b) {
         Inertia in = kBox;
         in.mass = -2.0;
         b.add_link(link("l2", in));
       },
       "test.urdf:l2: link 'l2'", "mass: must not be negative"},
      {"unknown frame link",
       [](ModelBuilder& b) {
         b.add_frame(FrameSpec{"tool", "nope", Pose(), "test:tool"});
       },
       "test:tool: frame 'tool'", "no link or frame named 'nope'"},
  };
  for (const Case& c : cases) {
    ModelBuilder b;
    base(b);
    c.edit(b);
    const std::string msg = build_error(b);
    EXPECT_EQ(msg.rfind(c.prefix, 0), 0u) << c.what << ": " << msg;
    EXPECT_NE(msg.find(c.expected), std::string::npos) << c.what << ": " << msg;
  }
}

TEST(ValidateModel, RejectsAHandCorruptedModel) {
  ModelBuilder b;
  b.add_link(link("l0", kBox));
  b.add_link(link("l1", kBox));
  b.add_joint(joint("j1", JointSpecType::kRevolute, "l0", "l1"));
  Model m = b.build();
  m.joints[1].axis = Vector3(0, 0, 2);
  EXPECT_THROW(validate_model(m), Error);
  m.joints[1].axis = Vector3::UnitZ();
  m.bodies[1].inertia = Inertia{};
  EXPECT_THROW(validate_model(m), Error) << "massless leaf: M(0) singular";
}

}  // namespace
}  // namespace extwrench
