#pragma once
// `pointhaptics study` and `pointhaptics fit`: commands written in Python, because their engine is (Dask
// distributed runs the simulations, SciPy fits the parameters); the command line hands them over.
#include <string>
#include <vector>

namespace pointhaptics::cli {

/// Replaces this process by Debian's python3 running `module` (pointhaptics.studies, ...) with `args`. The
/// package is taken from the build tree when run from it (PH_PYTHON_BUILD_DIR), else from where it was
/// installed. Returns only on failure (an exit code, the reason printed).
int run_python_module(const std::string& module, const std::vector<std::string>& args);

}  // namespace pointhaptics::cli
