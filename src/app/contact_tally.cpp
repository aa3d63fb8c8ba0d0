#include "extwrench/app/contact_tally.hpp"

#include <algorithm>
#include <cstdio>

#include "extwrench/core/time_step.hpp"

namespace extwrench {

ContactTally::ContactTally(int bodies)
    : samples_by_link(static_cast<std::size_t>(std::max(bodies, 0)), 0) {}

void ContactTally::add(double t, bool contact, int link, bool disagreement) {
  if (rows == 0) t_begin = t;
  if (rows > 0 && t - t_end > longest_step) {
    longest_step = t - t_end;
    longest_step_at = t;
  }
  t_end = t;
  ++rows;
  if (contact) {
    ++contact_samples;
    if (disagreement) ++disagreement_samples;
    if (!in_contact_) ++contact_episodes;
    if (link >= 0 && static_cast<std::size_t>(link) < samples_by_link.size())
      ++samples_by_link[static_cast<std::size_t>(link)];
  }
  in_contact_ = contact;
}

double ContactTally::disagreement_fraction() const {
  return contact_samples > 0
             ? static_cast<double>(disagreement_samples) / static_cast<double>(contact_samples)
             : 0.0;
}

std::string contact_summary(const ContactTally& tally, const Model& model) {
  char head[128];
  std::snprintf(head, sizeof head, "contact: %ld of %ld samples (%.1f %%), %ld episode%s",
                tally.contact_samples, tally.rows,
                100.0 * static_cast<double>(tally.contact_samples) /
                    static_cast<double>(std::max(tally.rows, 1L)),
                tally.contact_episodes, tally.contact_episodes == 1 ? "" : "s");
  std::string text = head;
  const char* sep = "; ";
  const std::size_t links = std::min(tally.samples_by_link.size(), model.bodies.size());
  for (std::size_t l = 0; l < links; ++l) {
    if (tally.samples_by_link[l] == 0) continue;
    text += sep + model.bodies[l].name + " " + std::to_string(tally.samples_by_link[l]);
    sep = ", ";
  }
  return text;
}

std::string disagreement_warning(const ContactTally& tally) {
  // A few flagged samples happen at contact edges; a majority over a real contact does not.
  constexpr long kMinContactSamples = 20;
  if (tally.contact_samples < kMinContactSamples ||
      2 * tally.disagreement_samples <= tally.contact_samples)
    return {};
  char pct[32];
  std::snprintf(pct, sizeof pct, "%.0f %%", 100.0 * tally.disagreement_fraction());
  return std::string(pct) + " of the " + std::to_string(tally.contact_samples) +
         " contact samples carry 'disagreement' (the base sensor and the joint residual do not "
         "agree): check the sensor pose (sensor.pose, or the model's 'sensor' frame), the robot "
         "model (masses, inertias, joint order), the sensor's calibration (bias: sensor.tare) and "
         "the joints' friction and torque offsets, which the residual sees and the sensor does "
         "not (`extwrench calibrate` on a contact-free log, docs/calibration.md)";
}

std::string base_contact_warning(const ContactTally& tally, const Model& model) {
  constexpr long kMinContactSamples = 20;
  const long on_base = tally.samples_by_link.empty() ? 0 : tally.samples_by_link.front();
  if (tally.contact_samples < kMinContactSamples || 2 * on_base <= tally.contact_samples) return {};
  char pct[32];
  std::snprintf(pct, sizeof pct, "%.0f %%",
                100.0 * static_cast<double>(on_base) / static_cast<double>(tally.contact_samples));
  const std::string base = model.bodies.empty() ? "link 0" : model.bodies.front().name;
  return std::string(pct) + " of the " + std::to_string(tally.contact_samples) +
         " contact samples are on the base (" + base +
         ", status base_only): the base sensor reads a wrench the robot's motion does not explain "
         "while the joints feel nothing. Unless the base itself was pushed, check the sensor: its "
         "sign convention (the reading is what the robot discharges onto it: at rest f_m = M g, "
         "pointing down; docs/conventions.md#the-base-sensor), its pose (sensor.pose, or the "
         "model's 'sensor' frame; rpy in "
         "radians) and its bias (sensor.tare), and the robot's mass";
}

std::string frequent_alarms_note(const ContactTally& tally) {
  // A model error false-alarms in either of two ways (the real Panda uncalibrated: 35-45
  // episodes in 10.5 s; the paper arm with unmodelled friction: 99 % of the samples, 1-3 episodes,
  // on 3-5 links as the motion moves the error between joints). A real contact is declared once
  // and stays on its link; two pushes of 1 s in 4 s, one of them split by the paper's rule
  // between its link and one below, covered 52 % of the samples on 3 links
  // (examples/python/threshold_sweep.py at tau_min = 0.37 N m).
  constexpr long kMinEpisodes = 10;
  constexpr double kMinEpisodesPerSecond = 1.0;
  constexpr double kMostSamples = 0.8;
  constexpr double kLinkShare = 0.02;  // of the contact samples, for a link to count
  constexpr int kMinLinks = 3;
  if (tally.rows == 0 || tally.contact_samples == 0) return {};
  const double share = static_cast<double>(tally.contact_samples) / static_cast<double>(tally.rows);
  int links = 0, links_named = 0;  // with kLinkShare of the samples, and with any (as listed)
  for (const long count : tally.samples_by_link) {
    if (static_cast<double>(count) >= kLinkShare * static_cast<double>(tally.contact_samples))
      ++links;
    if (count > 0) ++links_named;
  }
  const bool frequent =
      tally.contact_episodes >= kMinEpisodes &&
      static_cast<double>(tally.contact_episodes) >= kMinEpisodesPerSecond * tally.duration();
  const bool wandering = share >= kMostSamples && links >= kMinLinks;
  if (!frequent && !wandering) return {};
  char text[160];
  std::snprintf(text, sizeof text,
                "contact declared on %.0f %% of the samples, %ld time%s in %.1f s, on %d links",
                100.0 * share, tally.contact_episodes, tally.contact_episodes == 1 ? "" : "s",
                tally.duration(), links_named);
  return std::string(text) +
         ": what a robot moving freely shows when its thresholds lie below what its model misses "
         "(friction, torque offsets, noise). If nothing touched the robot, calibrate on a "
         "contact-free log and include the result (`extwrench calibrate --config CONFIG.yaml "
         "--log FREE.csv --out CALIB.yaml`, then `calibration: CALIB.yaml` in the "
         "configuration; docs/calibration.md)";
}

std::string time_step_note(const ContactTally& tally) {
  const std::string slow = slow_time_step(tally.t_begin, tally.t_end, tally.rows);
  if (slow.empty()) return {};
  return slow +
         ", and a robot's controller logs at 100 Hz to 1 kHz. If t is in milliseconds or counts "
         "samples, convert it: the observer and the filters integrate over these steps";
}

std::string time_gap_note(const ContactTally& tally) {
  constexpr double kGap = 0.05;  // [s]: under 20 Hz
  constexpr double kTimesTheMean = 20.0;
  if (tally.rows < 3) return {};
  const double mean = tally.duration() / static_cast<double>(tally.rows - 1);
  if (!(tally.longest_step > kGap && tally.longest_step > kTimesTheMean * mean)) return {};
  char gap[32], step[32];
  std::snprintf(gap, sizeof gap, "%.4g", tally.longest_step);
  std::snprintf(step, sizeof step, "%.3g", mean);
  return std::string("the log has a gap: ") + gap +
         " s between t = " + time_text(tally.longest_step_at - tally.longest_step) + " and " +
         time_text(tally.longest_step_at) + " s, against " + step + " s per step on average" +
         ". The observer integrates it as one step, so its residual jumps there and the "
         "estimates after it settle again; replay the parts before and after it as two logs";
}

}  // namespace extwrench
