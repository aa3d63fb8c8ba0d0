// Inertia arithmetic and Model look-ups.
#include "extwrench/model/model.hpp"

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

bool Model::is_ancestor(int ancestor, int body) const {
  if (ancestor < 0 || body < 0 || body >= num_bodies()) return false;
  for (int b = body; b >= 0; b = parents[static_cast<std::size_t>(b)]) {
    if (b == ancestor) return true;
  }
  return false;
}

}  // namespace extwrench
