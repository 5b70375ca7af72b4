#pragma once
/// @file Reading scene files (TOML, design.md schema) with toml++.
#include <pointhaptics/io/scene.hpp>

#include <string>
#include <string_view>
#include <vector>

namespace pointhaptics {

/// One key of a scene set from outside the file (`pointhaptics run --set material.young=2e5`, a study's
/// varied parameter): a dotted path to the key ("material.young"; an array of tables takes an index,
/// "load.0.total") and its value as TOML ("2e5", "[0, -0.01, 0]", "\"neo_hookean\""; a bare word that is not
/// TOML, such as neo_hookean, is taken as a string). Tables on the way are made when missing.
struct SceneSetting {
  std::string key;
  std::string value;
};

/// "key=value" -> SceneSetting; throws Error naming the text when there is no '=' or no key.
SceneSetting parse_scene_setting(std::string_view text);

/// Parse a scene file, with `settings` applied over it. Unknown keys, wrong types, out-of-range values and
/// TOML syntax errors throw Error with one line "FILE:LINE: key: problem" (a set key: "FILE: key (set to
/// VALUE): problem").
Scene read_scene_file(const std::string& path, const std::vector<SceneSetting>& settings = {});

/// Parse scene text; `name` stands for the file in messages, relative paths resolve against `base_dir`.
Scene parse_scene(std::string_view text, const std::string& name = "<string>", const std::string& base_dir = ".",
                  const std::vector<SceneSetting>& settings = {});

}  // namespace pointhaptics
