#pragma once
/// @file The one exception type the library throws for bad input or a failed computation.
#include <stdexcept>
#include <string>

namespace pointhaptics {

/// A named, user-facing error: the message is one line that names the file, key, point or step at fault.
class Error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace pointhaptics
