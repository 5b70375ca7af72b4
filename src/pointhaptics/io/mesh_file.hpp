#pragma once
/// @file Reading surface meshes (OBJ, STL, PLY, and the other formats assimp reads).
#include <pointhaptics/geometry/triangle_mesh.hpp>

#include <string>

namespace pointhaptics {

/// The triangles of every mesh in the file, joined (assimp: triangulated, identical vertices merged).
/// Throws Error naming the file when it cannot be read or holds no triangle.
TriangleMesh read_mesh(const std::string& path);

/// Whether a .ply file's header declares faces (then it is a surface mesh, else a point cloud).
bool ply_has_faces(const std::string& path);

}  // namespace pointhaptics
