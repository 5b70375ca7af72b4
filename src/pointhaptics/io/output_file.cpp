#include <pointhaptics/io/output_file.hpp>

#include <pointhaptics/core/error.hpp>

#include <fmt/format.h>

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include <filesystem>
#include <system_error>

namespace pointhaptics {

namespace fs = std::filesystem;

void check_output_path(const std::string& path, std::string_view what) {
  if (path.empty()) throw Error(fmt::format("{}: no file name given", what));
  std::error_code ec;
  const fs::file_status status = fs::status(path, ec);
  if (fs::is_directory(status)) throw Error(fmt::format("{} {}: is a folder, not a file", what, path));
  if (fs::exists(status)) {
    if (::access(path.c_str(), W_OK) != 0) throw Error(fmt::format("{} {}: the file cannot be written", what, path));
    return;
  }
  const fs::path parent = fs::path(path).parent_path().empty() ? fs::path(".") : fs::path(path).parent_path();
  if (!fs::is_directory(parent, ec)) throw Error(fmt::format("{} {}: the folder {} does not exist", what, path, parent.string()));
  if (::access(parent.c_str(), W_OK) != 0)
    throw Error(fmt::format("{} {}: the folder {} cannot be written", what, path, parent.string()));
}

void TextOutput::flush() {
  const char* data = buffer_.data();
  std::size_t left = buffer_.size();
  while (left > 0) {
    const ssize_t n = ::write(fd_, data, left);
    if (n < 0) {
      if (errno == EINTR) continue;
      throw std::system_error(errno, std::generic_category());
    }
    data += n;
    left -= static_cast<std::size_t>(n);
  }
  buffer_.clear();
}

void write_text_file(const std::string& path, std::string_view what, const std::function<void(TextOutput&)>& write) {
  std::error_code ec;
  const fs::file_status status = fs::status(path, ec);
  if (fs::is_directory(status)) throw Error(fmt::format("{} {}: is a folder, not a file", what, path));
  // a device or FIFO is written in place: renaming a file over /dev/full would replace the device
  const bool in_place = fs::exists(status) && !fs::is_regular_file(status);
  const std::string target = in_place ? path : path + ".partial";
  const int fd = ::open(target.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) throw Error(fmt::format("{} {}: cannot write ({})", what, path, std::strerror(errno)));
  const auto give_up = [&](const std::string& reason) {
    if (!in_place) fs::remove(target, ec);
    throw Error(fmt::format("{} {}: cannot write ({})", what, path, reason));
  };
  try {
    TextOutput out(fd);
    write(out);
    out.flush();
  } catch (const std::system_error& e) {
    ::close(fd);
    give_up(e.code().message());
  } catch (...) {
    ::close(fd);
    if (!in_place) fs::remove(target, ec);
    throw;
  }
  if (::close(fd) != 0) give_up(std::strerror(errno));
  if (in_place) return;
  fs::rename(target, path, ec);
  if (ec) give_up(ec.message());
}

}  // namespace pointhaptics
