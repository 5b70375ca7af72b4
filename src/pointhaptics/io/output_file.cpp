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
  if (!fs::is_directory(parent, ec))
    throw Error(fmt::format("{} {}: the folder {} does not exist", what, path, parent.string()));
  if (::access(parent.c_str(), W_OK) != 0)
    throw Error(fmt::format("{} {}: the folder {} cannot be written", what, path, parent.string()));
}

TextOutput::TextOutput(std::string path, std::string what) : path_(std::move(path)), what_(std::move(what)) {
  std::error_code ec;
  const fs::file_status status = fs::status(path_, ec);
  if (fs::is_directory(status)) throw Error(fmt::format("{} {}: is a folder, not a file", what_, path_));
  // a device or FIFO is written in place: renaming a file over /dev/full would replace the device
  in_place_ = fs::exists(status) && !fs::is_regular_file(status);
  target_ = in_place_ ? path_ : path_ + ".partial";
  fd_ = ::open(target_.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd_ < 0) throw Error(fmt::format("{} {}: cannot write ({})", what_, path_, std::strerror(errno)));
}

TextOutput::~TextOutput() {
  if (fd_ < 0) return;
  ::close(fd_);
  std::error_code ec;
  if (!in_place_) fs::remove(target_, ec);
}

void TextOutput::flush() {
  const char* data = buffer_.data();
  std::size_t left = buffer_.size();
  while (left > 0 && error_ == 0) {
    const ssize_t n = ::write(fd_, data, left);
    if (n < 0) {
      if (errno != EINTR) error_ = errno;
      continue;
    }
    data += n;
    left -= static_cast<std::size_t>(n);
  }
  buffer_.clear();
}

void TextOutput::commit() {
  flush();
  const int fd = fd_;
  fd_ = -1;
  if (::close(fd) != 0 && error_ == 0) error_ = errno;
  std::error_code ec;
  if (error_ == 0 && !in_place_) {
    fs::rename(target_, path_, ec);
    if (ec) error_ = ec.value();
  }
  if (error_ != 0) {
    if (!in_place_) fs::remove(target_, ec);
    throw Error(fmt::format("{} {}: cannot write ({})", what_, path_, std::strerror(error_)));
  }
}

void write_text_file(const std::string& path, std::string_view what, const std::function<void(TextOutput&)>& write) {
  TextOutput out(path, std::string(what));
  write(out);
  out.commit();
}

}  // namespace pointhaptics
