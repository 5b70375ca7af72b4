#include <pointhaptics/io/input_file.hpp>

#include <pointhaptics/core/error.hpp>

#include <fmt/format.h>

#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <filesystem>

namespace pointhaptics {

std::uintmax_t check_input_file(const std::string& path, std::string_view what) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::file_status status = fs::status(path, ec);
  if (!fs::exists(status)) throw Error(fmt::format("{}: cannot open the {}: no such file", path, what));
  if (fs::is_directory(status)) throw Error(fmt::format("{}: the {} is a folder, not a file", path, what));
  if (!fs::is_regular_file(status))
    throw Error(fmt::format("{}: the {} is not a regular file (a device, FIFO or socket)", path, what));
  if (::access(path.c_str(), R_OK) != 0) throw Error(fmt::format("{}: cannot open the {}: not readable", path, what));
  const std::uintmax_t size = fs::file_size(path, ec);
  if (ec) throw Error(fmt::format("{}: cannot read the {} ({})", path, what, ec.message()));
  return size;
}

std::string file_extension(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext;
}

}  // namespace pointhaptics
