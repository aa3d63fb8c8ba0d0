// Helpers shared by the MuJoCo reference tests (test_mujoco_reference.cpp, test_mjcf.cpp):
// owning pointers, MuJoCo poses and vectors as ours, the worst error of a run.
#pragma once

#include <mujoco/mujoco.h>

#include <algorithm>
#include <cstdio>
#include <memory>
#include <string>

#include "extwrench/core/types.hpp"

namespace extwrench::test {

struct MjModelDeleter {
  void operator()(mjModel* m) const { mj_deleteModel(m); }
};
struct MjDataDeleter {
  void operator()(mjData* d) const { mj_deleteData(d); }
};
using MjModelPtr = std::unique_ptr<mjModel, MjModelDeleter>;
using MjDataPtr = std::unique_ptr<mjData, MjDataDeleter>;

inline Vector3 mj_vec3(const mjtNum* p) { return {p[0], p[1], p[2]}; }

/// World pose from MuJoCo's position and row-major 3x3 matrix (xpos/xmat, geom_xpos/xmat, ...).
inline Pose mj_pose(const mjtNum* pos, const mjtNum* mat) {
  Pose X;
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) X.rotation(i, j) = mat[3 * i + j];
    X.translation[i] = pos[i];
  }
  return X;
}

/// Body b's world pose after mj_kinematics.
inline Pose body_pose(const mjData* d, int b) { return mj_pose(d->xpos + 3 * b, d->xmat + 9 * b); }

/// The largest error of a run, printed when the test ends (the figures the reports quote).
struct Worst {
  std::string what;
  double value = 0.0;
  void update(double e) { value = std::max(value, e); }
  ~Worst() { std::printf("[ worst    ] %-48s %.3e\n", what.c_str(), value); }
};

}  // namespace extwrench::test
