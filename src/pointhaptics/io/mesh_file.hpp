#pragma once
/// @file Reading surface meshes (OBJ, STL, PLY, and the other formats assimp reads) and writing them (STL, PLY, OBJ).
#include <pointhaptics/geometry/triangle_mesh.hpp>

#include <string>
#include <string_view>

namespace pointhaptics {

/// The triangles of every mesh in the file, joined (assimp: triangulated, identical vertices merged).
/// Throws Error naming the file when it cannot be read or holds no triangle.
TriangleMesh read_mesh(const std::string& path);

/// Write `mesh` to `path` in the format its extension names: .stl (binary STL), .ply (binary PLY) or .obj
/// (Wavefront, no material file); assimp writes it, in single precision as those formats hold it. Written
/// beside the target and renamed over it (output_file.hpp). Throws Error naming `what` (e.g. "--surface")
/// and the path for another extension or a failed write.
void write_mesh(const std::string& path, const TriangleMesh& mesh, std::string_view what);

/// Whether a .ply file's header declares faces (then it is a surface mesh, else a point cloud).
bool ply_has_faces(const std::string& path);

}  // namespace pointhaptics
