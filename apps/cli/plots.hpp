#pragma once
/// @file Running the experiments' matplotlib scripts (scripts/plot_*.py; installed to share/pointhaptics).
#include <string>

namespace pointhaptics::experiments {

/// Runs `script_name` (e.g. "plot_cantilever.py") on the output folder with Debian's python3: the
/// given path if not empty, else the source tree's copy, else the installed one. Returns 0, or 1 with a
/// message on stderr when the script is missing or fails.
int run_plot_script(const std::string& script_name, const std::string& out_dir, const std::string& given = "");

}  // namespace pointhaptics::experiments
