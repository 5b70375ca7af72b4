#pragma once
/// @file The library's precompiled headers and GoogleTest's, for the test programs.
#include "library_pch.hpp"

#include <gtest/gtest.h>
