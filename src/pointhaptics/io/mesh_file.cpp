#include <pointhaptics/io/mesh_file.hpp>

#include <pointhaptics/core/error.hpp>
#include <pointhaptics/io/input_file.hpp>

#include <assimp/Importer.hpp>
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <fmt/format.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

namespace pointhaptics {

TriangleMesh read_mesh(const std::string& path) {
  check_input_file(path, "mesh file");
  Assimp::Importer importer;
  const aiScene* scene = importer.ReadFile(path, aiProcess_Triangulate | aiProcess_JoinIdenticalVertices);
  if (!scene) throw Error(fmt::format("{}: cannot read the mesh: {}", path, importer.GetErrorString()));
  TriangleMesh mesh;
  std::size_t n_vertices = 0;
  for (unsigned m = 0; m < scene->mNumMeshes; ++m) n_vertices += scene->mMeshes[m]->mNumVertices;
  mesh.V.resize(3, static_cast<Eigen::Index>(n_vertices));
  index_t base = 0;
  for (unsigned m = 0; m < scene->mNumMeshes; ++m) {
    const aiMesh* am = scene->mMeshes[m];
    for (unsigned v = 0; v < am->mNumVertices; ++v)
      mesh.V.col(base + static_cast<index_t>(v)) = Vec3(am->mVertices[v].x, am->mVertices[v].y, am->mVertices[v].z);
    for (unsigned f = 0; f < am->mNumFaces; ++f) {
      const aiFace& face = am->mFaces[f];
      if (face.mNumIndices != 3) continue;  // points and lines of a mixed file
      mesh.F.push_back({base + static_cast<index_t>(face.mIndices[0]), base + static_cast<index_t>(face.mIndices[1]),
                        base + static_cast<index_t>(face.mIndices[2])});
    }
    base += static_cast<index_t>(am->mNumVertices);
  }
  if (mesh.F.empty()) throw Error(fmt::format("{}: the file holds no triangle", path));
  // STL repeats every vertex per triangle; assimp's joining keeps them apart across meshes, so join
  // exact duplicates here too, which the closedness check needs
  std::map<std::array<double, 3>, index_t> unique;
  std::vector<index_t> remap(static_cast<std::size_t>(mesh.V.cols()));
  Points joined(3, mesh.V.cols());
  index_t n = 0;
  for (index_t v = 0; v < mesh.V.cols(); ++v) {
    const std::array<double, 3> k{mesh.V(0, v), mesh.V(1, v), mesh.V(2, v)};
    auto [it, fresh] = unique.emplace(k, n);
    if (fresh) joined.col(n++) = mesh.V.col(v);
    remap[static_cast<std::size_t>(v)] = it->second;
  }
  mesh.V = joined.leftCols(n);
  for (auto& f : mesh.F)
    for (index_t& i : f) i = remap[static_cast<std::size_t>(i)];
  return mesh;
}

bool ply_has_faces(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::string line;
  // the header only, however many comment or property lines it has (a mesh with over 1000 was taken for a
  // cloud), within a bound on its bytes
  for (std::size_t read = 0; read < (1u << 24) && std::getline(in, line); read += line.size() + 1) {
    if (line.rfind("end_header", 0) == 0) break;
    std::istringstream words(line);
    std::string keyword, element;
    long long count = 0;
    words >> keyword >> element >> count;
    if (keyword == "element" && element == "face" && count > 0) return true;
  }
  return false;
}

}  // namespace pointhaptics
