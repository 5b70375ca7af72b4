#pragma once
/// @file The reduced model's basis kept on disk (`[reduction] cache`): the set-up's factor, modes and derivatives
/// are made once per object and read back by the next run in milliseconds. A file is named by a key hashed from
/// everything the basis depends on, so a changed object, material, held face, load or setting finds no file and
/// makes (and keeps) its own. A file that cannot be read (truncated, damaged, another format) is never used: the
/// basis is made again and the reason is reported.
#include <pointhaptics/reduction/modal_basis.hpp>

#include <cstdint>
#include <optional>
#include <string>

namespace pointhaptics {

/// The content key of the basis `build_modal_basis(model, settings)` (carried from a sampling at `basis_spacing`
/// when it is > 0) would make: a 64-bit FNV-1a hash of the points, masses, stiffness volumes, neighbourhoods and
/// their MLS and hourglass coefficients, the Lame parameters, the held points, the constant loads, the settings
/// and the file format's version.
std::uint64_t basis_key(const Model& model, const ModalBasisSettings& settings, double basis_spacing);

/// The folder `[reduction] cache = "auto"` keeps bases in: $POINTHAPTICS_CACHE_DIR, else
/// $XDG_CACHE_HOME/pointhaptics, else $HOME/.cache/pointhaptics; empty when none of them is set.
std::string default_basis_cache_dir();

/// The file of the basis with `key` in folder `dir`: dir/reduction-<key as 16 hex digits>.basis.
std::string basis_cache_file(const std::string& dir, std::uint64_t key);

/// What reading a cache file gave: the basis, or why there is none (`missing` when there is no file at all).
struct CachedBasis {
  std::optional<ModalBasis> basis;
  bool missing = false;
  std::string why;  ///< when there is no basis: what was wrong with the file
};

/// Reads `file` as the basis with `key` for `n_points` points and `size` vectors. Never throws: a missing,
/// truncated or damaged file, another key or shape, or non-finite numbers come back as no basis and a reason.
CachedBasis read_basis_cache(const std::string& file, std::uint64_t key, index_t n_points, int size);

/// Writes `basis` with `key` to `file` (its folder made when missing), atomically: into a temporary file beside
/// it, renamed over `file` only once complete. Throws Error naming the file and the cause (a full disk, a
/// folder that cannot be written) and leaves no partial file.
void write_basis_cache(const std::string& file, std::uint64_t key, const ModalBasis& basis);

}  // namespace pointhaptics
