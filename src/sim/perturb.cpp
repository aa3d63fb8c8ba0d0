#include "extwrench/sim/perturb.hpp"

#include <string>

#include "extwrench/core/error.hpp"
#include "extwrench/sim/random.hpp"

namespace extwrench::sim {

Model perturb_model(const Model& model, double fraction, std::uint64_t seed) {
  if (!(fraction >= 0.0 && fraction < 0.5)) {
    throw Error("perturb_model: fraction must be in [0, 0.5), got " + std::to_string(fraction));
  }
  Rng rng(seed);
  // Additive error within ±fraction of each entry's own nominal value (paper Sec. IV): x (1 + u).
  auto perturb = [&](double x) { return x * (1.0 + rng.uniform(-fraction, fraction)); };
  Model out = model;
  for (Body& body : out.bodies) {
    Inertia& in = body.inertia;
    in.mass = perturb(in.mass);
    for (int k = 0; k < 3; ++k) in.com[k] = perturb(in.com[k]);
    Matrix3& I = in.inertia_com;
    const double xx = perturb(I(0, 0));
    const double xy = perturb(I(0, 1));
    const double xz = perturb(I(0, 2));
    const double yy = perturb(I(1, 1));
    const double yz = perturb(I(1, 2));
    const double zz = perturb(I(2, 2));
    I << xx, xy, xz, xy, yy, yz, xz, yz, zz;
  }
  return out;
}

}  // namespace extwrench::sim
