# warnings and code-generation flags shared by every target, as one interface target; only
# -march=native (PH_NATIVE) reaches consumers of the installed package
add_library(pointhaptics_build_flags INTERFACE)
add_library(pointhaptics::build_flags ALIAS pointhaptics_build_flags)
target_compile_options(pointhaptics_build_flags INTERFACE
  $<BUILD_INTERFACE:$<$<CXX_COMPILER_ID:GNU,Clang>:-Wall -Wextra -Wpedantic>>)
if(PH_WARNINGS_AS_ERRORS)
  target_compile_options(pointhaptics_build_flags INTERFACE $<BUILD_INTERFACE:-Werror>)
endif()
if(PH_NATIVE)
  # exported too: Eigen's allocation alignment depends on the instruction set, so code that shares
  # Eigen objects with a -march=native build must be compiled with the same flag
  target_compile_options(pointhaptics_build_flags INTERFACE -march=native)
endif()
if(PH_SANITIZE)
  target_compile_options(pointhaptics_build_flags INTERFACE
    $<BUILD_INTERFACE:-fsanitize=${PH_SANITIZE} -fno-omit-frame-pointer -fno-sanitize-recover=all>)
  target_link_options(pointhaptics_build_flags INTERFACE $<BUILD_INTERFACE:-fsanitize=${PH_SANITIZE}>)
endif()
install(TARGETS pointhaptics_build_flags EXPORT PointHapticsTargets)
# GCC 12 reports -Wmaybe-uninitialized inside its own AVX-512 intrinsics when Eigen vectorises for
# -march=native (a known false positive in avx512fintrin.h, not in our code)
if(PH_NATIVE AND CMAKE_CXX_COMPILER_ID STREQUAL "GNU" AND CMAKE_CXX_COMPILER_VERSION VERSION_LESS 13)
  target_compile_options(pointhaptics_build_flags INTERFACE $<BUILD_INTERFACE:-Wno-maybe-uninitialized>)
endif()
# ... and under ASan + UBSan at -O1 it reports copies of std::optional and std::function in the standard
# headers (std::regex's states, optional regions of a scene) as maybe uninitialized: GCC's documented false
# positives with -fsanitize, not in our code (the optimised build reports none)
if(PH_SANITIZE MATCHES "address" AND CMAKE_CXX_COMPILER_ID STREQUAL "GNU")
  target_compile_options(pointhaptics_build_flags INTERFACE $<BUILD_INTERFACE:-Wno-maybe-uninitialized>)
endif()
# ... and under TSan GCC warns (-Wtsan) at every std::atomic_thread_fence it inlines, since TSan does not model
# fences. Our code has none (the lock-free buffers use acquire/release operations on the atomics themselves); the
# ones it sees are Boost.Asio's (the Haply device's WebSocket, haptics/devices/haply_device.cpp), whose tests are
# not in the threaded set TSan runs.
if(PH_SANITIZE MATCHES "thread" AND CMAKE_CXX_COMPILER_ID STREQUAL "GNU")
  target_compile_options(pointhaptics_build_flags INTERFACE $<BUILD_INTERFACE:-Wno-tsan>)
endif()
