#pragma once
/// @file Reading scene files (TOML, design.md schema) with toml++.
#include <pointhaptics/io/scene.hpp>

#include <string>
#include <string_view>

namespace pointhaptics {

/// Parse a scene file. Unknown keys, wrong types, out-of-range values and TOML syntax errors throw
/// Error with one line "FILE:LINE: key: problem".
Scene read_scene_file(const std::string& path);

/// Parse scene text; `name` stands for the file in messages, relative paths resolve against `base_dir`.
Scene parse_scene(std::string_view text, const std::string& name = "<string>", const std::string& base_dir = ".");

}  // namespace pointhaptics
