#include "plots.hpp"

#include <fmt/format.h>

#include <cstdlib>
#include <filesystem>

#ifndef PH_SCRIPTS_SOURCE_DIR
#define PH_SCRIPTS_SOURCE_DIR ""
#endif
#ifndef PH_SCRIPTS_INSTALLED_DIR
#define PH_SCRIPTS_INSTALLED_DIR ""
#endif

namespace pointhaptics::experiments {

int run_plot_script(const std::string& script_name, const std::string& out_dir, const std::string& given) {
  namespace fs = std::filesystem;
  std::string script = given;
  for (const char* dir : {PH_SCRIPTS_SOURCE_DIR, PH_SCRIPTS_INSTALLED_DIR})
    if (script.empty() && *dir && fs::exists(fs::path(dir) / script_name))
      script = (fs::path(dir) / script_name).string();
  if (script.empty()) {
    fmt::print(stderr, "pointhaptics: {} not found; CSV and summary written, no plots\n", script_name);
    return 1;
  }
  // Debian's interpreter first: python3-matplotlib is installed for it, whatever else is on PATH
  const std::string python = fs::exists("/usr/bin/python3") ? "/usr/bin/python3" : "python3";
  const std::string command = fmt::format("{} '{}' '{}'", python, script, out_dir);
  if (std::system(command.c_str()) != 0) {
    fmt::print(stderr, "pointhaptics: the plots failed ({}); is python3-matplotlib installed?\n", command);
    return 1;
  }
  return 0;
}

}  // namespace pointhaptics::experiments
