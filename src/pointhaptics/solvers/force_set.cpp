#include <pointhaptics/solvers/force_set.hpp>

#include <pointhaptics/core/stage_timer.hpp>
#include <pointhaptics/mechanics/tangent_matrix.hpp>

namespace pointhaptics {

void ForceSet::clear() {
  members_.clear();
  terms_.members.clear();
}

void ForceSet::add_member(DynamicForces* forces) {
  members_.push_back(forces);
  if (EnergyTerm* term = forces->energy_term()) terms_.members.push_back(term);
}

double ForceSet::take_seconds() {
  const double seconds = seconds_ + terms_.seconds;
  seconds_ = terms_.seconds = 0;
  return seconds;
}

void ForceSet::add(const Model& model, const State& state, Points& f) {
  timed_stage(seconds_, [&] {
    for (DynamicForces* m : members_) m->add(model, state, f);
  });
}

bool ForceSet::add_stiffness(const Model& model, const State& state,
                             Eigen::Matrix<double, 9, Eigen::Dynamic>& springs) {
  bool any = false;
  timed_stage(seconds_, [&] {
    for (DynamicForces* m : members_) any = m->add_stiffness(model, state, springs) || any;
  });
  return any;
}

double ForceSet::max_point_stiffness() const {
  double sum = 0;
  for (const DynamicForces* m : members_) sum += m->max_point_stiffness();
  return sum;
}

bool ForceSet::add_beyond_energy(const Model& model, const State& state, Points& f) {
  bool any = false;
  timed_stage(seconds_, [&] {
    for (DynamicForces* m : members_) any = m->add_beyond_energy(model, state, f) || any;
  });
  return any;
}

void ForceSet::after_step(const Model& model, const State& state, Workspace& ws) {
  timed_stage(seconds_, [&] {
    for (DynamicForces* m : members_) m->after_step(model, state, ws);
  });
}

double ForceSet::Terms::energy(const Model& model, const Points& u) {
  double sum = 0;
  timed_stage(seconds, [&] {
    for (EnergyTerm* t : members) sum += t->energy(model, u);
  });
  return sum;
}

void ForceSet::Terms::add_forces(const Model& model, const Points& u, Points& f) {
  timed_stage(seconds, [&] {
    for (EnergyTerm* t : members) t->add_forces(model, u, f);
  });
}

void ForceSet::Terms::linearise(const Model& model, const Points& u, TangentMode mode) {
  timed_stage(seconds, [&] {
    for (EnergyTerm* t : members) t->linearise(model, u, mode);
  });
}

void ForceSet::Terms::add_tangent_product(const Points& dx, Points& out) const {
  timed_stage(seconds, [&] {
    for (const EnergyTerm* t : members) t->add_tangent_product(dx, out);
  });
}

void ForceSet::Terms::add_diagonal_blocks(Eigen::Matrix<double, 9, Eigen::Dynamic>& blocks) const {
  for (const EnergyTerm* t : members) t->add_diagonal_blocks(blocks);
}

bool ForceSet::Terms::add_to_matrix(TangentMatrix& K) const {
  for (const EnergyTerm* t : members) {
    if (t->add_to_matrix(K)) continue;
    // (a member without coupling; none of today's: it allocates)
    const index_t n = static_cast<index_t>(K.diagonal.size());
    Eigen::Matrix<double, 9, Eigen::Dynamic> blocks = Eigen::Matrix<double, 9, Eigen::Dynamic>::Zero(9, n);
    t->add_diagonal_blocks(blocks);
    for (index_t i = 0; i < n; ++i)
      for (int a = 0; a < 9; ++a) K.values[9 * static_cast<std::size_t>(K.diagonal[i]) + a] += blocks(a, i);
  }
  return true;
}

bool ForceSet::Terms::update_multipliers(const Model& model, const Points& u) {
  bool met = true;
  timed_stage(seconds, [&] {
    for (EnergyTerm* t : members) met = t->update_multipliers(model, u) && met;
  });
  return met;
}

}  // namespace pointhaptics
