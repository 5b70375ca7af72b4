#pragma once
/// @file The third-party headers that nearly every translation unit of the library includes, precompiled once
/// (cmake/PointHapticsPrecompiledHeaders.cmake): Eigen's dense module alone is about 123k preprocessed lines,
/// 8-11 s at -O3 in each file that includes it.
#include <Eigen/Dense>
#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <limits>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <variant>
#include <vector>
