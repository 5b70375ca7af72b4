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

/// A file (text, or bytes through write()) written beside its target and renamed over it by commit(), so that an interrupted run or a
/// full disk never leaves a truncated file and a file written before stays as it was; a device or FIFO
/// (e.g. /dev/stdout) is written in place. print() buffers and never throws: a failed write (a full disk)
/// is kept, later prints are dropped, and commit() reports it. So a file can be streamed through a long run
/// without the run failing on it. fmt's own output_file flushes in its destructor, where a full disk
/// terminated the program.
class TextOutput {
 public:
  /// Opens the temporary file; throws Error naming `what` and the path if it cannot.
  TextOutput(std::string path, std::string what);
  /// Without commit(), the temporary file is removed and the target left as it was.
  ~TextOutput();
  TextOutput(const TextOutput&) = delete;
  TextOutput& operator=(const TextOutput&) = delete;

  template <class... T>
  void print(fmt::format_string<T...> format, T&&... args) {
    if (error_ != 0) return;
    fmt::format_to(std::back_inserter(buffer_), format, std::forward<T>(args)...);
    if (buffer_.size() > (1u << 20)) flush();
  }
  /// Append raw bytes (a binary file written through the same guarantees).
  void write(std::string_view bytes) {
    if (error_ != 0) return;
    buffer_.append(bytes.data(), bytes.data() + bytes.size());
    if (buffer_.size() > (1u << 20)) flush();
  }
  /// Write out, close and rename over the target; throws Error naming `what`, the path and the system's
  /// reason if any write failed.
  void commit();

 private:
  void flush();
  std::string path_, what_, target_;
  bool in_place_ = false;
  int fd_ = -1;
  int error_ = 0;  ///< errno of the first failed write
  fmt::memory_buffer buffer_;
};

/// Write a whole text file through `write` (a TextOutput, committed at the end).
void write_text_file(const std::string& path, std::string_view what, const std::function<void(TextOutput&)>& write);

}  // namespace pointhaptics
