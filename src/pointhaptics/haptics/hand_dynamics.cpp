#include <pointhaptics/haptics/hand_dynamics.hpp>

#include <pointhaptics/core/error.hpp>

namespace pointhaptics {

HandEndpoint::HandEndpoint(const HandDynamics& hand, const Vec3& start) : hand_(hand), x_(start) {
  if (!(hand.mass > 0) || !(hand.stiffness >= 0) || !(hand.damping >= 0))
    throw Error("hand dynamics: the hand needs a positive mass and non-negative stiffness and damping");
}

}  // namespace pointhaptics
