// A tiny project built against the installed PointHaptics package (find_package + pointhaptics::pointhaptics).
#include <pointhaptics/pointhaptics.hpp>
#include <cstdio>
int main() {
  auto scene = pointhaptics::parse_scene("[object]\nshape = \"box\"\nsize = [0.03, 0.01, 0.01]\nspacing = 0.005\n");
  pointhaptics::Simulation sim(pointhaptics::build_scene_model(scene), scene.solver);
  sim.step();
  std::printf("%d points\n", sim.model().n_points);
  return sim.model().n_points == 63 ? 0 : 1;
}
