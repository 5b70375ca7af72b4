#pragma once
/// @file `pointhaptics experiment contact-pairs` (issue 47): each kind of contact pair checked against what
/// statics says it must carry: a block resting on a table, a block on a block on a table, two tools pinching a
/// sample (its weight by friction, slipping below W / 2N), two jaws lifting a sample off a table, and a cut piece
/// falling onto a table.
#include <string>

namespace pointhaptics::experiments {

struct ContactPairsOptions {
  std::string out = "contact-pairs-out";
  int threads = 2;
  std::string plot_script;  ///< plot_contact_pairs.py to use (empty: the source tree's or the installed one)
};

/// Writes contact-pairs.csv, summary.md and contact-pairs.png into options.out; returns the exit code (0 when
/// every check holds).
int run_contact_pairs_experiment(const ContactPairsOptions& options);

}  // namespace pointhaptics::experiments
