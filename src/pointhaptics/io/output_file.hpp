#pragma once
/// @file Output files that a reader never sees half written, and that are checked before a run starts.
#include <fmt/format.h>

#include <functional>
#include <iterator>
#include <string>
#include <string_view>

namespace pointhaptics {

/// Check, before anything is computed, that `path` can be written: its folder exists and is writable,
/// and the path itself is not a folder (nor a file that cannot be written). Throws Error naming `what`
/// (e.g. "--json") and the path. Creates nothing.
void check_output_path(const std::string& path, std::string_view what);

/// Formatted text to a file, buffered; a failed write throws (from print() or at the end), never from a
/// destructor (fmt's own output_file flushes in its destructor, so a full disk terminated the program).
class TextOutput {
 public:
  template <class... T>
  void print(fmt::format_string<T...> format, T&&... args) {
    fmt::format_to(std::back_inserter(buffer_), format, std::forward<T>(args)...);
    if (buffer_.size() > (1u << 20)) flush();
  }
  /// Write what is buffered; throws std::system_error with the system's reason.
  void flush();
  explicit TextOutput(int fd) : fd_(fd) {}

 private:
  fmt::memory_buffer buffer_;
  int fd_;
};

/// Write a text file through `write`: into a temporary file beside it, renamed over `path` once complete,
/// so that an interrupted run or a full disk never leaves a truncated file and a file written before stays
/// as it was. A device or FIFO (e.g. /dev/stdout) is written in place. A write error is an Error naming
/// `what` and the path, with the system's reason.
void write_text_file(const std::string& path, std::string_view what, const std::function<void(TextOutput&)>& write);

}  // namespace pointhaptics
