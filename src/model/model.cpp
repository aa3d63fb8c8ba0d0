// Inertia arithmetic and Model look-ups.
#include "extwrench/model/model.hpp"

#include <string>
#include <vector>

#include "extwrench/core/error.hpp"

namespace extwrench {

namespace {

// Rotational inertia of a point mass m at offset d: m (|d|^2 1 - d d^T) (parallel-axis term).
Matrix3 parallel_axis(double m, const Vector3& d) {
  return m * (d.squaredNorm() * Matrix3::Identity() - d * d.transpose());
}

}  // namespace

Inertia Inertia::operator+(const Inertia& other) const {
  Inertia sum;
  sum.mass = mass + other.mass;
  if (sum.mass > 0.0) {
    sum.com = (mass * com + other.mass * other.com) / sum.mass;
  } else {
    // Two massless bodies: the CoM is undefined; the origin keeps the result finite, and the
    // rotational inertia of a massless body does not depend on the reference point.
    sum.com.setZero();
  }
  // Steiner: move both inertias from their own CoM to the common CoM.
  sum.inertia_com = inertia_com + parallel_axis(mass, com - sum.com) + other.inertia_com +
                    parallel_axis(other.mass, other.com - sum.com);
  return sum;
}

Inertia Inertia::transformed(const Pose& X_AB) const {
  Inertia out;
  out.mass = mass;
  out.com = X_AB.act(com);
  out.inertia_com = X_AB.rotation * inertia_com * X_AB.rotation.transpose();
  return out;
}

bool Model::is_serial_chain() const {
  for (int i = 1; i < num_bodies(); ++i) {
    if (parents[static_cast<std::size_t>(i)] != i - 1) return false;
  }
  return true;
}

double Model::total_mass() const {
  double m = 0.0;
  for (const Body& b : bodies) m += b.inertia.mass;
  return m;
}

std::optional<int> Model::find_body(std::string_view name) const {
  for (std::size_t i = 0; i < bodies.size(); ++i) {
    if (bodies[i].name == name) return static_cast<int>(i);
  }
  if (const auto f = find_frame(name)) return frames[static_cast<std::size_t>(*f)].body;
  return std::nullopt;
}

std::optional<int> Model::find_frame(std::string_view name) const {
  for (std::size_t i = 0; i < frames.size(); ++i) {
    if (frames[i].name == name) return static_cast<int>(i);
  }
  return std::nullopt;
}

std::optional<int> Model::find_joint(std::string_view name) const {
  // joints[0] is the root's unused placeholder: never a match.
  for (std::size_t i = 1; i < joints.size(); ++i) {
    if (joints[i].name == name) return static_cast<int>(i);
  }
  return std::nullopt;
}

int Model::body_index(std::string_view name) const {
  if (const auto b = find_body(name)) return *b;
  throw Error("model '" + this->name + "': no body or frame named '" + std::string(name) + "'");
}

int Model::frame_index(std::string_view name) const {
  if (const auto f = find_frame(name)) return *f;
  throw Error("model '" + this->name + "': no frame named '" + std::string(name) + "'");
}

bool Model::has_armature() const {
  for (std::size_t i = 1; i < joints.size(); ++i) {
    if (joints[i].armature != 0.0) return true;
  }
  return false;
}

bool Model::is_ancestor(int ancestor, int body) const {
  if (ancestor < 0 || body < 0 || body >= num_bodies()) return false;
  for (int b = body; b >= 0; b = parents[static_cast<std::size_t>(b)]) {
    if (b == ancestor) return true;
  }
  return false;
}

std::string describe_branches(const Model& model) {
  const auto nb = static_cast<std::size_t>(model.num_bodies());
  std::vector<std::vector<int>> children(nb);
  std::vector<int> subtree(nb, 1);  // bodies under each, itself included
  for (std::size_t i = 1; i < nb; ++i) {
    const int p = model.parents[i];
    if (p < 0 || static_cast<std::size_t>(p) >= i) return "(parents out of order)";
    children[static_cast<std::size_t>(p)].push_back(static_cast<int>(i));
  }
  for (std::size_t i = nb; i-- > 1;)
    subtree[static_cast<std::size_t>(model.parents[i])] += subtree[i];
  // Each branch names its first kMax joints (depth first) and counts the rest; at most
  // kMaxBranchings branching bodies are listed: the message stays short on any tree.
  constexpr int kMax = 4;
  constexpr int kMaxBranchings = 5;
  const auto branch = [&](int first) {
    std::string names;
    int named = 0;
    for (std::vector<int> stack{first}; !stack.empty() && named < kMax; ++named) {
      const auto b = static_cast<std::size_t>(stack.back());
      stack.pop_back();
      names += (names.empty() ? "'" : ", '") + model.joints[b].name + "'";
      stack.insert(stack.end(), children[b].rbegin(), children[b].rend());
    }
    const int rest = subtree[static_cast<std::size_t>(first)] - named;
    if (rest > 0) names += " and " + std::to_string(rest) + " more";
    return "branch " + names;
  };
  std::string out;
  int branchings = 0;
  for (std::size_t i = 0; i < nb; ++i) {
    if (children[i].size() < 2) continue;
    if (++branchings > kMaxBranchings) continue;
    out += (out.empty() ? "" : "; ") + std::string("body '") + model.bodies[i].name + "': ";
    for (std::size_t c = 0; c < children[i].size(); ++c)
      out += (c == 0 ? "" : ", ") + branch(children[i][c]);
  }
  if (branchings > kMaxBranchings)
    out += "; and " + std::to_string(branchings - kMaxBranchings) + " more branching bodies";
  return out;
}

}  // namespace extwrench
