// What a replay's estimates look like at a glance: how many samples declare a contact, how often
// a contact starts, on which links. `extwrench estimate` prints it per log, and its two rules tell
// a model's error (false alarms all over the motion) and a doubtful sensor apart from a touch; the
// Python `estimate` applies the same rules to its arrays.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "extwrench/model/model.hpp"

namespace extwrench {

struct ContactTally {
  long rows = 0;
  long contact_samples = 0;       ///< estimates with a contact declared
  long disagreement_samples = 0;  ///< of those, flagged `disagreement`
  long contact_episodes = 0;      ///< contacts declared anew (a contact sample after a free one)
  /// Contact samples by the estimate's link, index 0..n (0: link 0, seen by the base sensor only).
  std::vector<long> samples_by_link;
  double t_begin = 0.0;  ///< the first and last sample's time [s]
  double t_end = 0.0;
  double longest_step = 0.0;     ///< the longest time step between two samples [s]
  double longest_step_at = 0.0;  ///< the time of the sample that ends it [s]

  ContactTally() = default;
  /// For a robot of `bodies` bodies (Model::num_bodies(), n + 1).
  explicit ContactTally(int bodies);

  /// One estimate: its time, whether it declares a contact, its link (counted when 0 <= link <
  /// bodies) and whether it carries `disagreement`.
  void add(double t, bool contact, int link, bool disagreement);

  [[nodiscard]] double duration() const { return t_end - t_begin; }
  /// disagreement_samples / contact_samples (0 without contact).
  [[nodiscard]] double disagreement_fraction() const;

 private:
  bool in_contact_ = false;
};

/// "contact: 586 of 4001 samples (14.6 %), 2 episodes; link4 223, link5 5, link6 354": links in
/// body order, those never declared left out.
[[nodiscard]] std::string contact_summary(const ContactTally& tally, const Model& model);

/// The warning for estimates whose contact samples mostly carry `disagreement` (the base sensor
/// and the joint residual tell different stories), naming the likely causes; empty when there is
/// nothing to warn about (fewer than half, or too few contact samples).
[[nodiscard]] std::string disagreement_warning(const ContactTally& tally);

/// The warning for estimates whose contacts lie mostly on link 0 (at least 20 contact samples,
/// more than half of them): the base sensor reads a wrench the robot's motion does not explain
/// while the joint residual stays quiet. Over a log that is a sensor whose sign convention, pose
/// or bias is wrong more often than a push on the base; the warning names both. Empty otherwise.
[[nodiscard]] std::string base_contact_warning(const ContactTally& tally, const Model& model);
/// The note for estimates whose contacts look like a model's error rather than a touch: declared
/// anew at least once a second (10 times or more), or on 80 % of the samples or more, spread
/// over three links or more (each with 2 % of the contact samples); with the remedy (calibrate
/// on a contact-free log, docs/calibration.md). Empty otherwise. Meant for logs without truth
/// and configurations without a calibration: the caller decides.
[[nodiscard]] std::string frequent_alarms_note(const ContactTally& tally);

/// The note for a log whose samples are more than 50 ms apart on average (under 20 Hz, where a
/// robot's controller logs at 100 Hz to 1 kHz): its t is then likely not in seconds (milliseconds,
/// a sample counter), and the observer and the filters, which integrate over the time steps,
/// estimate nothing useful. Empty otherwise (and below two samples).
[[nodiscard]] std::string time_step_note(const ContactTally& tally);
/// The note for a gap in a log: one time step over 50 ms and 20 times the mean step, which the
/// observer integrates as one step (its momentum jumps). Empty otherwise.
[[nodiscard]] std::string time_gap_note(const ContactTally& tally);

}  // namespace extwrench
