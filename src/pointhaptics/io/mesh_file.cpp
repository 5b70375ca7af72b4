#include <pointhaptics/io/mesh_file.hpp>

#include <pointhaptics/core/error.hpp>
#include <pointhaptics/io/input_file.hpp>
#include <pointhaptics/io/output_file.hpp>

#include <assimp/Exporter.hpp>
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

void write_mesh(const std::string& path, const TriangleMesh& mesh, std::string_view what) {
  const std::string ext = file_extension(path);
  const char* format = ext == ".stl" ? "stlb" : ext == ".ply" ? "plyb" : ext == ".obj" ? "objnomtl" : nullptr;
  if (!format)
    throw Error(fmt::format("{} {}: '{}' is not a mesh format this writes (.stl, .ply or .obj)", what, path, ext));
  // one mesh under the root node; aiScene's destructor frees what is given to it
  aiScene scene;
  scene.mRootNode = new aiNode();
  scene.mRootNode->mNumMeshes = 1;
  scene.mRootNode->mMeshes = new unsigned[1]{0};
  scene.mNumMaterials = 1;
  scene.mMaterials = new aiMaterial* [1] { new aiMaterial() };
  scene.mNumMeshes = 1;
  scene.mMeshes = new aiMesh* [1] { new aiMesh() };
  aiMesh& out = *scene.mMeshes[0];
  out.mMaterialIndex = 0;
  out.mPrimitiveTypes = aiPrimitiveType_TRIANGLE;
  out.mNumVertices = static_cast<unsigned>(mesh.V.cols());
  out.mVertices = new aiVector3D[out.mNumVertices];
  for (unsigned v = 0; v < out.mNumVertices; ++v)
    out.mVertices[v] = aiVector3D(static_cast<ai_real>(mesh.V(0, v)), static_cast<ai_real>(mesh.V(1, v)),
                                  static_cast<ai_real>(mesh.V(2, v)));
  out.mNumFaces = static_cast<unsigned>(mesh.F.size());
  out.mFaces = new aiFace[out.mNumFaces];
  for (unsigned f = 0; f < out.mNumFaces; ++f) {
    out.mFaces[f].mNumIndices = 3;
    out.mFaces[f].mIndices = new unsigned[3];
    for (int k = 0; k < 3; ++k)
      out.mFaces[f].mIndices[k] = static_cast<unsigned>(mesh.F[f][static_cast<std::size_t>(k)]);
  }
  Assimp::Exporter exporter;
  const aiExportDataBlob* blob = exporter.ExportToBlob(&scene, format);
  if (!blob) throw Error(fmt::format("{} {}: cannot write the mesh: {}", what, path, exporter.GetErrorString()));
  // through the output file that renames into place, so that a full disk leaves no half mesh
  write_text_file(path, what, [&](TextOutput& file) {
    file.print("{}", std::string_view(static_cast<const char*>(blob->data), blob->size));
  });
}

bool ply_has_faces(const std::string& path) {
  check_input_file(path, "PLY file");
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
