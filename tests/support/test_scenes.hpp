#pragma once
// Scene files shared by the tests, as TOML text.
#include <pointhaptics/core/model.hpp>

#include <string>

namespace pointhaptics::test {

/// The seed's cantilever at 7.5 mm (21 x 5 x 5 points): clamped at x = 0, a tip traction of 0.01 N down,
/// E = 1e5 Pa, nu = 0.4, damping 20 / s; `solver` and `dt` as given, 2 s of dynamics.
inline std::string cantilever_scene(const std::string& solver = "explicit", const std::string& dt = "1e-3") {
  return R"(
[object]
shape = "box"
size = [0.15, 0.03, 0.03]
spacing = 0.0075
[material]
young = 1e5
poisson = 0.4
density = 1000.0
damping = 20.0
[[fixed]]
box = { min = [-1.0, -1.0, -1.0], max = [0.0, 1.0, 1.0] }
[[load]]
kind = "traction"
box = { min = [0.15, -1.0, -1.0], max = [1.0, 1.0, 1.0] }
total = [0.0, -0.01, 0.0]
[solver]
kind = ")" +
         solver + R"("
dt = )" + dt +
         R"(
duration = 2.0
)";
}

/// The seed cantilever's (cantilever_scene()) tip deflection: minus the mean u_y of its points at x = 0.15 m, m.
inline double cantilever_tip_deflection(const Model& model, const Points& u) {
  double tip = 0;
  int n = 0;
  for (index_t i = 0; i < model.n_points; ++i)
    if (model.X(0, i) == 0.15) {
      tip += u(1, i);
      ++n;
    }
  return -tip / n;
}

}  // namespace pointhaptics::test
