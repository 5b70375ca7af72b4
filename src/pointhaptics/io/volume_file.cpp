#include <pointhaptics/io/volume_file.hpp>

#include <pointhaptics/core/error.hpp>
#include <pointhaptics/core/memory_limit.hpp>
#include <pointhaptics/core/run_control.hpp>
#include <pointhaptics/io/input_file.hpp>

#include <fmt/format.h>
#include <nifti/nifti2_io.h>
#include <teem/nrrd.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <memory>

namespace pointhaptics {
namespace {

constexpr double max_voxels = 512.0 * 1024 * 1024;

bool ends_with(const std::string& s, const std::string& tail) {
  return s.size() >= tail.size() && std::equal(tail.rbegin(), tail.rend(), s.rbegin(), [](char a, char b) {
           return std::tolower(static_cast<unsigned char>(a)) == b;
         });
}

// The size a gzip stream says it inflates to: its trailer's ISIZE, the size modulo 2^32 (RFC 1952)
std::uint32_t gzip_inflated_size(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  in.seekg(-4, std::ios::end);
  unsigned char b[4] = {0, 0, 0, 0};
  in.read(reinterpret_cast<char*>(b), 4);
  return static_cast<std::uint32_t>(b[0]) | static_cast<std::uint32_t>(b[1]) << 8 |
         static_cast<std::uint32_t>(b[2]) << 16 | static_cast<std::uint32_t>(b[3]) << 24;
}

// Before an image is inflated or read: the memory its data and its float copy take, against what the process may
// still take, and a read that will be long announced (issue 52: a 2 MB .nii.gz inflated to 3.9 GB first)
void check_image_memory(const std::string& path, double voxels, double bytes_per_voxel) {
  const double needed = voxels * (bytes_per_voxel + sizeof(float));
  const MemoryLimit limit = memory_limit();
  if (needed > limit.bytes)
    throw Error(fmt::format("{}: its {:.3g} voxels would take {:.3g} GB read, more than {} ({:.3g} GB)", path, voxels,
                            needed / 1e9, limit.what, limit.bytes / 1e9));
  // about 1 GB/s to inflate and convert on the development machine
  if (needed > 2e9)
    announce(fmt::format("reading {:.3g} voxels from {}: about {}, {:.2g} GB", voxels, path,
                         format_duration(needed / 1e9), needed / 1e9));
}

double unit_of(const std::string& unit) {
  if (unit == "m" || unit == "meter" || unit == "metre") return 1.0;
  if (unit == "um" || unit == "micron") return 1e-6;
  return 1e-3;  // mm, and the default of both formats in practice
}

void check_affine(const Eigen::Matrix4d& A, const std::string& path) {
  // a voxel's edges: a spacing of 1e300 gave "inf lattice cells" later (issue 52)
  for (int a = 0; a < 3; ++a) {
    const double edge = A.col(a).head<3>().norm();
    if (!(edge >= 1e-9 && edge <= 1e3))
      throw Error(
          fmt::format("{}: the voxels measure {:.3g} m along axis {}: a voxel spacing must lie in [1e-9, 1e3] m "
                      "(after the file's units)",
                      path, edge, a));
  }
  if (!A.allFinite() || !(std::abs(A.topLeftCorner<3, 3>().determinant()) > 0))
    throw Error(fmt::format("{}: the voxel-to-world orientation is singular or not finite", path));
}

VolumeImage read_nifti(const std::string& path) {
  // the header first: sizes are checked before the data is allocated
  std::unique_ptr<nifti_image, void (*)(nifti_image*)> header(nifti_image_read(path.c_str(), 0), nifti_image_free);
  if (!header) throw Error(fmt::format("{}: not a readable NIfTI file", path));
  if (header->nx < 1 || header->ny < 1 || header->nz < 1 || header->nt > 1 || header->nu > 1 || header->nv > 1 ||
      header->nw > 1)
    throw Error(fmt::format("{}: a 3-D image is needed, this one is {}x{}x{}x{}", path, header->nx, header->ny,
                            header->nz, header->nt));
  if (static_cast<double>(header->nx) * static_cast<double>(header->ny) * static_cast<double>(header->nz) > max_voxels)
    throw Error(
        fmt::format("{}: {}x{}x{} voxels is more than this reader takes", path, header->nx, header->ny, header->nz));
  check_image_memory(path, static_cast<double>(header->nvox), header->nbyper);
  // where a single file's voxel data starts: after its header (348 bytes for NIfTI-1, 540 for NIfTI-2, then a
  // 4-byte extension flag), and within the file when it is not compressed (0, -100, NaN or 1e30 passed: issue 52)
  if (header->iname && header->fname && std::string(header->iname) == std::string(header->fname)) {
    const double smallest = header->nifti_type >= NIFTI_FTYPE_NIFTI2_1 ? 544 : 352;
    const double offset = static_cast<double>(header->iname_offset);
    const double largest = ends_with(path, ".nii") ? static_cast<double>(std::filesystem::file_size(path)) : 1e12;
    if (!(offset >= smallest && offset <= largest))
      throw Error(
          fmt::format("{}: vox_offset {} is out of range: the voxel data starts after the header, in [{:.0f}, "
                      "{:.0f}] bytes",
                      path, header->iname_offset, smallest, largest));
  }
  // a compressed file must inflate to what its header promises (its gzip trailer says, modulo 4 GiB) before it
  // is inflated
  if (ends_with(path, ".nii.gz")) {
    const double declared =
        static_cast<double>(header->iname_offset) + static_cast<double>(header->nvox) * header->nbyper;
    const auto declared_mod = static_cast<std::uint32_t>(std::fmod(declared, 4294967296.0));
    const std::uint32_t inflates = gzip_inflated_size(path);
    if (inflates != declared_mod)
      throw Error(
          fmt::format("{}: the compressed file inflates to {} bytes (modulo 4 GiB), not the {:.0f} its header "
                      "declares: truncated or corrupt",
                      path, inflates, declared));
  }
  // an uncompressed single file must hold what its header promises before that much memory is taken
  if (ends_with(path, ".nii") && header->iname && std::string(header->iname) == path) {
    const double needed =
        static_cast<double>(header->iname_offset) + static_cast<double>(header->nvox) * header->nbyper;
    if (static_cast<double>(std::filesystem::file_size(path)) < needed)
      throw Error(fmt::format("{}: truncated: the header promises {:.0f} bytes, the file has {}", path, needed,
                              std::filesystem::file_size(path)));
  }
  std::unique_ptr<nifti_image, void (*)(nifti_image*)> nim(nifti_image_read(path.c_str(), 1), nifti_image_free);
  if (!nim || !nim->data) throw Error(fmt::format("{}: the NIfTI data cannot be read (truncated?)", path));
  VolumeImage image;
  image.nx = static_cast<index_t>(nim->nx);
  image.ny = static_cast<index_t>(nim->ny);
  image.nz = static_cast<index_t>(nim->nz);
  const nifti_dmat44& m = nim->sform_code > 0 ? nim->sto_xyz : nim->qto_xyz;
  if (nim->sform_code > 0 || nim->qform_code > 0) {
    for (int r = 0; r < 4; ++r)
      for (int c = 0; c < 4; ++c) image.voxel_to_world(r, c) = m.m[r][c];
  } else {
    image.voxel_to_world.diagonal() << nim->dx, nim->dy, nim->dz, 1.0;
  }
  const double unit = nim->xyz_units == NIFTI_UNITS_METER ? 1.0 : nim->xyz_units == NIFTI_UNITS_MICRON ? 1e-6 : 1e-3;
  image.voxel_to_world.topRows<3>() *= unit;
  check_affine(image.voxel_to_world, path);
  const std::size_t n = static_cast<std::size_t>(nim->nvox);
  image.values.resize(n);
  const double slope = nim->scl_slope != 0 && std::isfinite(nim->scl_slope) ? nim->scl_slope : 1.0;
  const double inter = std::isfinite(nim->scl_inter) ? nim->scl_inter : 0.0;
  auto fill = [&](auto tag) {
    using T = decltype(tag);
    const T* data = static_cast<const T*>(nim->data);
    for (std::size_t v = 0; v < n; ++v)
      image.values[v] = static_cast<float>(slope * static_cast<double>(data[v]) + inter);
  };
  switch (nim->datatype) {
    case DT_UINT8: fill(std::uint8_t{}); break;
    case DT_INT8: fill(std::int8_t{}); break;
    case DT_INT16: fill(std::int16_t{}); break;
    case DT_UINT16: fill(std::uint16_t{}); break;
    case DT_INT32: fill(std::int32_t{}); break;
    case DT_UINT32: fill(std::uint32_t{}); break;
    case DT_FLOAT32: fill(float{}); break;
    case DT_FLOAT64: fill(double{}); break;
    default:
      throw Error(
          fmt::format("{}: NIfTI data type {} is not supported (integers and floats are)", path, nim->datatype));
  }
  return image;
}

// A NRRD's header alone (the data skipped), so that its sizes are checked before the data is allocated:
// a small file declaring 2000^3 voxels allocated gigabytes and hung (issue 21).
void check_nrrd_header(const std::string& path) {
  std::unique_ptr<Nrrd, Nrrd* (*)(Nrrd*)> header(nrrdNew(), nrrdNuke);
  std::unique_ptr<NrrdIoState, NrrdIoState* (*)(NrrdIoState*)> io(nrrdIoStateNew(), nrrdIoStateNix);
  io->skipData = AIR_TRUE;
  if (nrrdLoad(header.get(), path.c_str(), io.get())) return;  // nrrdLoad below names the problem
  double voxels = 1;
  for (unsigned a = 0; a < header->dim; ++a) voxels *= static_cast<double>(header->axis[a].size);
  if (voxels > max_voxels)
    throw Error(fmt::format("{}: the header declares {:.3g} voxels, more than this reader takes ({:.3g})", path, voxels,
                            max_voxels));
  if (header->type != nrrdTypeBlock) check_image_memory(path, voxels, static_cast<double>(nrrdTypeSize[header->type]));
  // raw data in the same file must be there before that much memory is taken
  const bool attached = io->dataFNArr->len == 0;
  if (attached && io->encoding == nrrdEncodingRaw && header->type != nrrdTypeBlock) {
    const double needed = voxels * static_cast<double>(nrrdTypeSize[header->type]);
    const double size = static_cast<double>(std::filesystem::file_size(path));
    if (size < needed)
      throw Error(
          fmt::format("{}: truncated: the header declares {:.0f} bytes of raw data, the file has {:.0f} bytes in all",
                      path, needed, size));
  }
}

VolumeImage read_nrrd(const std::string& path) {
  check_nrrd_header(path);
  std::unique_ptr<Nrrd, Nrrd* (*)(Nrrd*)> nrrd(nrrdNew(), nrrdNuke);
  if (nrrdLoad(nrrd.get(), path.c_str(), nullptr)) {
    char* err = biffGetDone(NRRD);
    std::string message = err ? err : "unknown error";
    free(err);
    while (!message.empty() && (message.back() == '\n' || message.back() == ' ')) message.pop_back();
    std::replace(message.begin(), message.end(), '\n', ' ');
    throw Error(fmt::format("{}: not a readable NRRD file: {}", path, message));
  }
  if (nrrd->dim != 3)
    throw Error(fmt::format("{}: a 3-D image is needed, this one has {} dimensions", path, nrrd->dim));
  if (nrrd->type == nrrdTypeBlock) throw Error(fmt::format("{}: block-typed NRRD data is not supported", path));
  VolumeImage image;
  image.nx = static_cast<index_t>(nrrd->axis[0].size);
  image.ny = static_cast<index_t>(nrrd->axis[1].size);
  image.nz = static_cast<index_t>(nrrd->axis[2].size);
  if (static_cast<double>(image.nx) * static_cast<double>(image.ny) * static_cast<double>(image.nz) > max_voxels)
    throw Error(fmt::format("{}: too many voxels", path));
  const double unit = nrrd->spaceDim > 0 && nrrd->spaceUnits[0] ? unit_of(nrrd->spaceUnits[0]) : 1e-3;
  for (int a = 0; a < 3; ++a) {
    if (nrrd->spaceDim == 3) {
      for (int r = 0; r < 3; ++r) image.voxel_to_world(r, a) = unit * nrrd->axis[a].spaceDirection[r];
    } else {
      const double s = std::isfinite(nrrd->axis[a].spacing) ? nrrd->axis[a].spacing : 1.0;
      image.voxel_to_world(a, a) = unit * s;
    }
  }
  if (nrrd->spaceDim == 3)
    for (int r = 0; r < 3; ++r)
      image.voxel_to_world(r, 3) = std::isfinite(nrrd->spaceOrigin[r]) ? unit * nrrd->spaceOrigin[r] : 0.0;
  check_affine(image.voxel_to_world, path);
  const std::size_t n =
      static_cast<std::size_t>(image.nx) * static_cast<std::size_t>(image.ny) * static_cast<std::size_t>(image.nz);
  image.values.resize(n);
  for (std::size_t v = 0; v < n; ++v) image.values[v] = static_cast<float>(nrrdDLookup[nrrd->type](nrrd->data, v));
  return image;
}

}  // namespace

bool is_volume_file(const std::string& path) {
  return ends_with(path, ".nii") || ends_with(path, ".nii.gz") || ends_with(path, ".nrrd") || ends_with(path, ".nhdr");
}

VolumeImage read_volume(const std::string& path) {
  check_input_file(path, "volume image");
  VolumeImage image = ends_with(path, ".nrrd") || ends_with(path, ".nhdr") ? read_nrrd(path) : read_nifti(path);
  for (std::size_t v = 0; v < image.values.size(); ++v) {
    if (v % 65536 == 0) throw_if_stop_requested("the image's intensities");
    if (!std::isfinite(image.values[v])) throw Error(fmt::format("{}: an intensity is not finite", path));
  }
  return image;
}

PointCloud sample_volume(const VolumeImage& image, double low, double high, double spacing, const std::string& name,
                         index_t max_points) {
  if (!(spacing > 0) || !std::isfinite(spacing)) throw Error(fmt::format("{}: spacing must be > 0 (m)", name));
  if (!(low <= high)) throw Error(fmt::format("{}: threshold [{}, {}] is empty", name, low, high));
  auto in_window = [&](double v) { return v >= low && v <= high; };
  // the world bounding box of the voxels in the window
  Vec3 lo = Vec3::Constant(INFINITY), hi = Vec3::Constant(-INFINITY);
  const Eigen::Matrix3d A = image.voxel_to_world.topLeftCorner<3, 3>();
  const Vec3 b = image.voxel_to_world.topRightCorner<3, 1>();
  std::size_t count = 0;
  for (index_t k = 0; k < image.nz; ++k)
    for (index_t j = 0; j < image.ny; ++j) {
      throw_if_stop_requested("the image's voxels");
      for (index_t i = 0; i < image.nx; ++i)
        if (in_window(image.at(i, j, k))) {
          const Vec3 x = A * Vec3(i, j, k) + b;
          lo = lo.cwiseMin(x);
          hi = hi.cwiseMax(x);
          ++count;
        }
    }
  if (count == 0) throw Error(fmt::format("{}: no voxel lies in the threshold window [{}, {}]", name, low, high));
  // half a voxel around the voxel centres
  const Vec3 half = 0.5 * A.cwiseAbs().rowwise().sum();
  lo -= half;
  hi += half;
  const Eigen::Array3d cells = ((hi - lo).array() / spacing - 1e-9).ceil().max(1.0);
  if (!(cells.prod() <= 8.0 * static_cast<double>(max_points)))
    throw Error(fmt::format("{}: a {:.3g} m spacing gives {:.3g} lattice cells: too many (coarser spacing?)", name,
                            spacing, cells.prod()));
  const Vec3 origin = 0.5 * (lo + hi) - 0.5 * (cells.matrix() - Vec3::Ones()) * spacing;
  const Eigen::Matrix3d to_voxel = A.inverse();
  std::vector<Vec3> points;
  std::vector<double> intensities;
  for (index_t c = 0; c < static_cast<index_t>(cells.prod()); ++c) {
    if (c % 4096 == 0) throw_if_stop_requested("the image's lattice");
    const index_t ci = c % static_cast<index_t>(cells.x()),
                  cj = (c / static_cast<index_t>(cells.x())) % static_cast<index_t>(cells.y()),
                  ck = c / static_cast<index_t>(cells.x() * cells.y());
    const Vec3 x = origin + spacing * Vec3(ci, cj, ck);
    const Vec3 v = to_voxel * (x - b);
    const index_t i = static_cast<index_t>(std::lround(v.x())), j = static_cast<index_t>(std::lround(v.y())),
                  k = static_cast<index_t>(std::lround(v.z()));
    if (i < 0 || j < 0 || k < 0 || i >= image.nx || j >= image.ny || k >= image.nz) continue;
    if (in_window(image.at(i, j, k))) {
      points.push_back(x);
      intensities.push_back(image.at(i, j, k));
    }
  }
  if (points.empty())
    throw Error(
        fmt::format("{}: no lattice point of spacing {:.3g} m falls in the window (finer spacing?)", name, spacing));
  if (static_cast<index_t>(points.size()) > max_points)
    throw Error(fmt::format("{}: {} points: too many (coarser spacing?)", name, points.size()));
  PointCloud cloud;
  cloud.spacing = spacing;
  cloud.X.resize(3, static_cast<Eigen::Index>(points.size()));
  for (std::size_t p = 0; p < points.size(); ++p) cloud.X.col(static_cast<Eigen::Index>(p)) = points[p];
  cloud.volume = Eigen::VectorXd::Constant(cloud.X.cols(), spacing * spacing * spacing);
  cloud.surface.assign(points.size(), 0);
  cloud.intensity =
      Eigen::Map<const Eigen::VectorXd>(intensities.data(), static_cast<Eigen::Index>(intensities.size()));
  return cloud;
}

}  // namespace pointhaptics
