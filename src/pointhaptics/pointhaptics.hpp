#pragma once
/// @file The public API in one include: scenes, models, the simulation and its results.
#include <pointhaptics/core/error.hpp>
#include <pointhaptics/core/model.hpp>
#include <pointhaptics/core/state.hpp>
#include <pointhaptics/io/output_file.hpp>
#include <pointhaptics/io/result_json.hpp>
#include <pointhaptics/io/scene_toml.hpp>
#include <pointhaptics/mechanics/energy.hpp>
#include <pointhaptics/scene_builder.hpp>
#include <pointhaptics/scene_session.hpp>
#include <pointhaptics/haptics/haptic_log.hpp>
#include <pointhaptics/interactive.hpp>
#include <pointhaptics/simulation.hpp>
#include <pointhaptics/vtk_output.hpp>
#include <pointhaptics/csv_output.hpp>
#include <pointhaptics/cut_surface.hpp>
#include <pointhaptics/object_surface.hpp>
