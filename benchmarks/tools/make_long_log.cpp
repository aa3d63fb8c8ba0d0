// Writes the long log of the replay benchmark (issue 5, acceptance 3): ROWS rows at 1 kHz of the
// paper arm's log format (7 joints, velocities, a 6-axis base reading, truth). Smooth synthetic
// signals, not a simulation: the replay's speed does not depend on what the numbers mean, and
// an hour of simulation would take longer than the replay it is meant to time.
//   usage: extwrench_make_log ROWS OUT.csv
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <exception>

#include "extwrench/io/log.hpp"

int main(int argc, char** argv) {
  if (argc != 3) {
    std::fprintf(stderr, "usage: %s ROWS OUT.csv\n", argv[0]);
    return 2;
  }
  const long rows = std::strtol(argv[1], nullptr, 10);
  if (rows < 1) {
    std::fprintf(stderr, "error: ROWS must be a positive integer, got '%s'\n", argv[1]);
    return 2;
  }
  try {
    using namespace extwrench;
    constexpr int n = 7;
    LogLayout layout{.n = n,
                     .velocity = true,
                     .force = true,
                     .moment = true,
                     .truth = true,
                     .true_tau_ext = true};
    LogWriter writer(argv[2], layout);
    Sample s;
    s.q.resize(n);
    s.dq.resize(n);
    s.tau.resize(n);
    s.truth.tau_ext = VectorX::Zero(n);
    for (long k = 0; k < rows; ++k) {
      const double t = 0.001 * static_cast<double>(k);
      for (int i = 0; i < n; ++i) {
        s.q[i] = 0.5 * std::sin(0.3 * t + i);
        s.dq[i] = 0.15 * std::cos(0.3 * t + i);
        s.tau[i] = 10.0 * std::sin(0.2 * t + i);
      }
      // A 20 N push on link 6 during the second half of every 10 s.
      const bool contact = std::fmod(t, 10.0) >= 5.0;
      s.t = t;
      s.reading_S << 1, 2, -170, 0.1, 0.2, 0.3;
      s.truth.link = contact ? "link6" : "";
      s.truth.body = contact ? 6 : -1;
      s.truth.contacts = contact ? 1 : 0;
      s.truth.force_W << (contact ? 20.0 : 0.0), 0, 0;
      s.truth.point_W << 0.1, 0.2, 0.8;
      writer.write(s);
    }
    writer.close();
  } catch (const std::exception& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 1;
  }
  return 0;
}
