# project options, prefixed PH_, defaulting to whether this is the top-level project
option(PH_BUILD_TESTS "Build the GoogleTest suite" ${PROJECT_IS_TOP_LEVEL})
option(PH_BUILD_APPS "Build the pointhaptics command line and the benchmark suite" ${PROJECT_IS_TOP_LEVEL})
option(PH_NATIVE "Optimise for the building machine's CPU (-march=native)" OFF)
option(PH_BUILD_PYTHON "Build the Python bindings (pybind11, NumPy)" ${PROJECT_IS_TOP_LEVEL})
option(PH_BUILD_VIEWER "Build the interactive viewer (GLFW, OpenGL, Dear ImGui; not in sanitizer builds)" ${PROJECT_IS_TOP_LEVEL})
option(PH_BUILD_FUZZERS "Build the libFuzzer targets (clang, with PH_SANITIZE including fuzzer-no-link)" OFF)
set(PH_SANITIZE "" CACHE STRING "Sanitizers to build with: address,undefined | thread | empty")
option(PH_WARNINGS_AS_ERRORS "Treat compiler warnings as errors (CI: scripts/test sets it when CI is set)" OFF)
