// Helpers shared by the io and reference tests: an independent forward kinematics over a Model, and
// DH products written directly from the textbook formulas (4x4 homogeneous transforms).
#pragma once

#include <Eigen/Geometry>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include "extwrench/io/robot_loader.hpp"
#include "extwrench/model/model.hpp"

namespace extwrench::test {

/// X_W,body for every body: X_{parent,i}(q) = placement * motion(axis, q).
inline std::vector<Pose> body_poses(const Model& m, const VectorX& q) {
  std::vector<Pose> X(static_cast<std::size_t>(m.num_bodies()));
  for (int i = 1; i < m.num_bodies(); ++i) {
    const auto ui = static_cast<std::size_t>(i);
    const Joint& j = m.joints[ui];
    Pose motion;
    if (j.type == JointType::kRevolute) {
      motion.rotation = Eigen::AngleAxisd(q[i - 1], j.axis).toRotationMatrix();
    } else {
      motion.translation = j.axis * q[i - 1];
    }
    X[ui] = X[static_cast<std::size_t>(m.parents[ui])] * j.placement * motion;
  }
  return X;
}

inline Pose world_frame_pose(const Model& m, const std::vector<Pose>& X, const std::string& frame) {
  const Frame& f = m.frames[static_cast<std::size_t>(m.frame_index(frame))];
  return X[static_cast<std::size_t>(f.body)] * f.placement;
}

inline Eigen::Isometry3d iso(const Pose& x) {
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  t.linear() = x.rotation;
  t.translation() = x.translation;
  return t;
}

/// Standard DH: A_i = Rz(theta) Tz(d) Tx(a) Rx(alpha).
inline Eigen::Isometry3d dh_standard(double a, double alpha, double d, double theta) {
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  t.rotate(Eigen::AngleAxisd(theta, Eigen::Vector3d::UnitZ()));
  t.translate(Eigen::Vector3d(0, 0, d));
  t.translate(Eigen::Vector3d(a, 0, 0));
  t.rotate(Eigen::AngleAxisd(alpha, Eigen::Vector3d::UnitX()));
  return t;
}

/// Modified (Craig) DH: A_i = Rx(alpha_{i-1}) Tx(a_{i-1}) Rz(theta_i) Tz(d_i).
inline Eigen::Isometry3d dh_modified(double a, double alpha, double d, double theta) {
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  t.rotate(Eigen::AngleAxisd(alpha, Eigen::Vector3d::UnitX()));
  t.translate(Eigen::Vector3d(a, 0, 0));
  t.rotate(Eigen::AngleAxisd(theta, Eigen::Vector3d::UnitZ()));
  t.translate(Eigen::Vector3d(0, 0, d));
  return t;
}

inline bool near(const Pose& x, const Eigen::Isometry3d& t, double tol) {
  return (x.rotation - t.linear()).cwiseAbs().maxCoeff() < tol &&
         (x.translation - t.translation()).norm() < tol;
}

/// Load options for tests that read only the kinematics and inertias: no meshes, no ROS path.
inline LoadOptions no_meshes() {
  LoadOptions o;
  o.load_meshes = false;
  o.use_ros_package_path = false;
  return o;
}

inline std::filesystem::path shared_models() {
  return std::filesystem::path(EXTWRENCH_SHARED_DIR) / "models";
}
inline bool have_shared() { return std::filesystem::is_directory(shared_models()); }
inline std::filesystem::path project_models() {
  return std::filesystem::path(EXTWRENCH_SOURCE_DIR) / "models";
}

}  // namespace extwrench::test
