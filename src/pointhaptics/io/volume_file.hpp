#pragma once
/// @file Medical volume images (NIfTI .nii/.nii.gz through nifti2, NRRD .nrrd/.nhdr through teem) and
/// their sampling into points where the intensity lies within a window.
#include <pointhaptics/core/point_cloud.hpp>

#include <string>
#include <vector>

namespace pointhaptics {

struct VolumeImage {
  index_t nx = 0, ny = 0, nz = 0;
  Eigen::Matrix4d voxel_to_world = Eigen::Matrix4d::Identity();  ///< voxel index (i, j, k, 1) -> position, m
  std::vector<float> values;                                     ///< scaled intensities, i fastest  (nx ny nz)
  double at(index_t i, index_t j, index_t k) const {
    const auto size = [](index_t v) { return static_cast<std::size_t>(v); };  // 512M voxels overflow index_t
    return values[size(i) + size(nx) * (size(j) + size(ny) * size(k))];
  }
};

/// Read a 3-D image: NIfTI-1/2 (the sform, else the qform, else the voxel sizes; units from xyzt_units,
/// millimetres when unknown; scl_slope/scl_inter applied; nifti2 sets non-finite floats to 0 as it reads)
/// or NRRD (space directions and origin, else axis spacings; space units, millimetres when unknown).
/// Throws Error naming the file for a missing, malformed or truncated file, fewer or more than 3 spatial
/// dimensions, more than 512M voxels, a singular orientation or (NRRD) non-finite values.
VolumeImage read_volume(const std::string& path);

/// Points on a lattice of `spacing` (m, centred on the voxels in the window) where the nearest voxel's
/// intensity lies in [low, high], each standing for spacing^3. Throws Error naming `name` if no voxel is
/// in the window or the lattice would be too large.
PointCloud sample_volume(const VolumeImage& image, double low, double high, double spacing, const std::string& name,
                         index_t max_points = 20'000'000);

/// Whether `path` names a volume image by its extension (.nii, .nii.gz, .nrrd, .nhdr).
bool is_volume_file(const std::string& path);

}  // namespace pointhaptics
