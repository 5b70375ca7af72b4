#pragma once
/// @file `pointhaptics experiment contact` (issue 16): a rigid sphere pressed into a block through the
/// object's surface, its force against depth beside Hertz's and a mesh-converged CalculiX model's
/// (fem/calculix_indentation), at two spacings; where the surface is first
/// felt; and the tool sliding at constant depth over the face.
#include <string>
#include <vector>

namespace pointhaptics::experiments {

struct ContactOptions {
  std::string out = "contact-out";
  bool quick = false;                 ///< the coarser spacing only, fewer depths (seconds)
  std::vector<int> per_radius{4, 8};  ///< spacings R / n
  /// the block's material: neo-Hookean by default (St. Venant-Kirchhoff collapses under the sphere past
  /// about 0.2 R in CalculiX and in the point model alike)
  std::string material = "neo_hookean";
  /// the contact's surface map: "exact" or "non_negative" (its negative weights left out; a scene's
  /// `[probe] surface_map`)
  std::string surface_map = "exact";
  /// CalculiX's element sizes at the contact, R / n: the last one is the reference, the others show its
  /// convergence (quick: 10 only)
  std::vector<int> fem_per_radius{10, 20, 40};
  /// > 0: the first spacing once more with the points near the contact (a box 1.2 R around it, down to 1.2 R
  /// deep) at spacing R / refine and the surface's edge half that ([[refine]]); 0: uniform samplings only
  int refine = 8;
  double friction = 0.3;  ///< Coulomb's coefficient of the friction run (the first sampling)
  /// the friction runs' quasi-static drag steps per spacing, one run each (quick: the last only); the last is
  /// the goal's and also runs refined
  std::vector<int> drag_steps{8, 16, 32};
  int threads = 0;          ///< 0: all
  std::string plot_script;  ///< plot_contact.py to use (default: the installed one)
};

/// Writes contact-force.csv, contact-calculix.csv, contact-sliding.csv, contact-friction.csv, summary.md and contact.png into options.out; returns the
/// exit code.
int run_contact_experiment(const ContactOptions& options);

}  // namespace pointhaptics::experiments
