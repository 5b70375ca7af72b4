#pragma once
/// @file How far the local contact model the haptic side renders between simulation updates strays from the
/// next update (issue 16, item 4): the previous model's force at the next model's probe position against the
/// force the simulation then found there. Kept on the simulation side (it sees every update); no allocation.
#include <pointhaptics/haptics/contact.hpp>
#include <pointhaptics/io/result_json.hpp>

#include <algorithm>

namespace pointhaptics {

class LocalModelStray {
 public:
  /// A new model `next` (`next_held`: its stiffness against the held object), compared with the one before it
  /// when both are in contact, and kept for the next.
  void add(const ContactModel& next, const Mat3& next_held);
  LocalModelSummary summary() const;

 private:
  struct Figure {
    double sum = 0, max = 0;
    void add(double x) {
      sum += x;
      max = std::max(max, x);
    }
  };
  ContactModel previous_;
  Mat3 previous_held_ = Mat3::Zero();
  long long updates_ = 0;
  double force_sum_ = 0;
  Figure rendered_, hold_, held_object_;
};

}  // namespace pointhaptics
