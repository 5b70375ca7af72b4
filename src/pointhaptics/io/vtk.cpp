#include <pointhaptics/io/vtk.hpp>

#include <pointhaptics/core/error.hpp>
#include <pointhaptics/io/output_file.hpp>

#include <fmt/format.h>
#include <fmt/os.h>

#include <filesystem>

namespace pointhaptics {

void write_vtp(const std::string& path, const Points& points, const std::vector<VtkArray>& arrays,
               const VtkTriangles& triangles) {
  const Eigen::Index n = points.cols();
  for (const VtkArray& a : arrays)
    if (a.components < 1 || static_cast<Eigen::Index>(a.values.size()) != a.components * n)
      throw Error(fmt::format("{}: array \"{}\" has {} values for {} points of {} components", path, a.name,
                              a.values.size(), n, a.components));
  write_text_file(path, "VTK frame", [&](TextOutput& out) {
    out.print(
        "<?xml version=\"1.0\"?>\n<VTKFile type=\"PolyData\" version=\"1.0\" byte_order=\"LittleEndian\">\n<PolyData>\n");
    const bool surface = !triangles.empty();
    out.print(
        "<Piece NumberOfPoints=\"{}\" NumberOfVerts=\"{}\" NumberOfLines=\"0\" NumberOfStrips=\"0\" NumberOfPolys=\"{}\">\n",
        n, surface ? 0 : n, triangles.size());
    out.print("<Points>\n<DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"ascii\">\n");
    for (Eigen::Index i = 0; i < n; ++i) out.print("{:.9g} {:.9g} {:.9g}\n", points(0, i), points(1, i), points(2, i));
    out.print("</DataArray>\n</Points>\n");
    if (surface) {
      out.print("<Polys>\n<DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">\n");
      for (const auto& t : triangles) out.print("{} {} {}\n", t[0], t[1], t[2]);
      out.print("</DataArray>\n<DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">\n");
      for (std::size_t k = 0; k < triangles.size(); ++k) out.print("{}\n", 3 * (k + 1));
      out.print("</DataArray>\n</Polys>\n<PointData>\n");
    } else {
      // every point a vertex cell, so that ParaView draws it without a glyph filter
      out.print("<Verts>\n<DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">\n");
      for (Eigen::Index i = 0; i < n; ++i) out.print("{}\n", i);
      out.print("</DataArray>\n<DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">\n");
      for (Eigen::Index i = 0; i < n; ++i) out.print("{}\n", i + 1);
      out.print("</DataArray>\n</Verts>\n<PointData>\n");
    }
    for (const VtkArray& a : arrays) {
      out.print("<DataArray type=\"{}\" Name=\"{}\" NumberOfComponents=\"{}\" format=\"ascii\">\n",
                a.integer ? "UInt8" : "Float64", a.name, a.components);
      for (Eigen::Index i = 0; i < n; ++i) {
        for (int c = 0; c < a.components; ++c) {
          const double v = a.values[static_cast<std::size_t>(i * a.components + c)];
          if (c) out.print(" ");
          if (a.integer) out.print("{}", static_cast<int>(v));
          else out.print("{:.9g}", v);
        }
        out.print("\n");
      }
      out.print("</DataArray>\n");
    }
    out.print("</PointData>\n</Piece>\n</PolyData>\n</VTKFile>\n");
  });
}

VtkSeries::VtkSeries(std::string folder, std::string base) : folder_(std::move(folder)), base_(std::move(base)) {
  std::error_code ec;
  std::filesystem::create_directories(folder_, ec);
  if (ec) throw Error(fmt::format("{}: cannot create the VTK output folder ({})", folder_, ec.message()));
  pvd_ = (std::filesystem::path(folder_) / (base_ + ".pvd")).string();
}

std::string VtkSeries::add(double time, const Points& points, const std::vector<VtkArray>& arrays) {
  const std::string name = fmt::format("{}_{:06d}.vtp", base_, frames_);
  std::string path = (std::filesystem::path(folder_) / name).string();
  write_vtp(path, points, arrays);
  entries_.push_back({time, 0, name});
  ++frames_;
  write_collection();
  return path;
}

std::string VtkSeries::add_surface(const Points& vertices, const VtkTriangles& triangles,
                                   const std::vector<VtkArray>& arrays) {
  if (frames_ == 0) throw Error(fmt::format("{}: a surface needs its frame first", pvd_));
  const std::string name = fmt::format("{}_surface_{:06d}.vtp", base_, frames_ - 1);
  std::string path = (std::filesystem::path(folder_) / name).string();
  write_vtp(path, vertices, arrays, triangles);
  entries_.push_back({entries_.back().time, 1, name});
  write_collection();
  return path;
}

void VtkSeries::write_collection() const {
  write_text_file(pvd_, "VTK collection", [&](TextOutput& out) {
    out.print(
        "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"1.0\" byte_order=\"LittleEndian\">\n<Collection>\n");
    for (const Entry& e : entries_)
      out.print("<DataSet timestep=\"{:.9g}\" group=\"\" part=\"{}\" file=\"{}\"/>\n", e.time, e.part, e.file);
    out.print("</Collection>\n</VTKFile>\n");
  });
}

}  // namespace pointhaptics
