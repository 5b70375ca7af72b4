#pragma once
// Opening scenes in the tests: on two threads, and the error a scene's text gets (read, and opened).
#include <pointhaptics/core/error.hpp>
#include <pointhaptics/io/scene_toml.hpp>
#include <pointhaptics/session/scene_session.hpp>

#include <string>
#include <utility>

namespace pointhaptics::test {

inline SessionOptions two_threads() {
  SessionOptions options;
  options.threads = 2;
  return options;
}

/// The message of the Error reading `text` (as "scene.toml") and, with `open`, building it gets; "no error".
inline std::string error_of(const std::string& text, bool open = true) {
  try {
    Scene scene = parse_scene(text, "scene.toml");
    if (open) SceneSession s = open_scene(std::move(scene), two_threads());
  } catch (const Error& e) {
    return e.what();
  }
  return "no error";
}

}  // namespace pointhaptics::test
