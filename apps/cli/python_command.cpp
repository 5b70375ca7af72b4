#include "python_command.hpp"

#include <fmt/format.h>

#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <filesystem>

#ifndef PH_PYTHON_BUILD_DIR
#define PH_PYTHON_BUILD_DIR ""
#endif

namespace pointhaptics::cli {

int run_python_module(const std::string& module, const std::vector<std::string>& args) {
  namespace fs = std::filesystem;
  // the package of this build when it has one (run from the build tree), else the installed one
  const fs::path build_package = fs::path(PH_PYTHON_BUILD_DIR) / "pointhaptics" / "__init__.py";
  if (*PH_PYTHON_BUILD_DIR && fs::exists(build_package)) {
    const char* old = std::getenv("PYTHONPATH");
    const std::string path =
        old && *old ? fmt::format("{}:{}", PH_PYTHON_BUILD_DIR, old) : std::string(PH_PYTHON_BUILD_DIR);
    setenv("PYTHONPATH", path.c_str(), 1);
  }
  // Debian's interpreter: python3-distributed, -pandas, -scipy and -matplotlib are installed for it
  const std::string python = fs::exists("/usr/bin/python3") ? "/usr/bin/python3" : "python3";
  std::vector<std::string> words = {python, "-m", module};
  words.insert(words.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (std::string& w : words) argv.push_back(w.data());
  argv.push_back(nullptr);
  execvp(argv[0], argv.data());
  fmt::print(stderr,
             "pointhaptics: error: cannot run {} ({}); the studies need python3 with python3-distributed, "
             "python3-pandas and python3-scipy\n",
             python, std::strerror(errno));
  return 1;
}

}  // namespace pointhaptics::cli
