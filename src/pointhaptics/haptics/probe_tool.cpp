#include <pointhaptics/haptics/probe_tool.hpp>

#include <pointhaptics/haptics/coupling.hpp>

namespace pointhaptics {

ProbeTool::ProbeTool(const Model& model, const ProbeParams& params, double coupling_stiffness, double max_force)
    : contact_(model, params), k_(coupling_stiffness), max_force_(max_force), scratch_(Points::Zero(3, model.n_points)) {}

void ProbeTool::place(const Model& model, const State& state, const Vec3& device, bool button) {
  device_ = device;
  button_ = button;
  contacts_before_ = last_.contacts;
  if (!device.allFinite()) {
    probe_ = device;
    return;
  }
  Vec3 p = probe_.allFinite() ? probe_ : device;
  for (int it = 0; it < 8; ++it) {
    scratch_.setZero();
    // the state is the same at every iteration: the positions and their grid are made once
    const Vec3 next = coupled_probe(contact_.apply(model, state.u, p, button, state.time, scratch_, it > 0), device, k_, max_force_);
    const bool settled = (next - p).norm() < 1e-9 + 1e-6 * contact_.params().radius;
    p = next;
    if (settled) break;
  }
  probe_ = p;
}

void ProbeTool::add(const Model& model, const State& state, Points& f) {
  last_ = contact_.apply(model, state.u, probe_, button_, state.time, f);
}

bool ProbeTool::add_stiffness(const Model&, const State&, Eigen::Matrix<double, 9, Eigen::Dynamic>& springs) {
  contact_.add_stiffness(springs);
  return last_.contacts > 0;
}

void ProbeTool::remap(const Model& model, const std::vector<index_t>& new_index) {
  contact_.remap(model, new_index);
  scratch_ = Points::Zero(3, model.n_points);
}

}  // namespace pointhaptics
