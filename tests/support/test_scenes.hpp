#pragma once
// Scene files shared by the tests, as TOML text.
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

}  // namespace pointhaptics::test
