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
#include <set>
#include <vector>
#include <sstream>

namespace pointhaptics {

namespace {

// A PLY file's header, read once, within a bound on its bytes: whether it declares faces (then it is a surface
// mesh, else a point cloud), and its first malformed line, if any. assimp's PLY reader loops for ever on
// malformed headers (found by fuzz_mesh_ply: no end_header line, a mangled property line), so a mesh's header is
// checked here before assimp reads it.
struct PlyHeader {
  bool faces = false;
  std::string problem;  ///< empty: a well-formed header
};

PlyHeader scan_ply_header(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::string line;
  PlyHeader header;
  const auto note = [&](int line_no, std::string_view why) {
    if (header.problem.empty())
      header.problem = fmt::format("{}:{}: not a PLY header line ({}): \"{}\"", path, line_no, why, line.substr(0, 80));
  };
  const auto is_type = [](const std::string& t) {
    static const std::set<std::string> types = {"char",  "uchar",  "short",   "ushort", "int",   "uint",
                                                "float", "double", "int8",    "uint8",  "int16", "uint16",
                                                "int32", "uint32", "float32", "float64"};
    return types.count(t) > 0;
  };
  int line_no = 0;
  // however many comment or property lines it has (a mesh with over 1000 was taken for a cloud)
  for (std::size_t read = 0; read < (1u << 24) && std::getline(in, line); read += line.size() + 1) {
    ++line_no;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    std::istringstream words(line);
    std::vector<std::string> w;
    for (std::string word; words >> word;) w.push_back(word);
    if (line.rfind("end_header", 0) == 0) {
      if (w.size() != 1 || w[0] != "end_header") note(line_no, "expected end_header alone");
      return header;
    }
    if (line_no == 1) {
      if (line != "ply") note(line_no, "a PLY file starts with \"ply\"");
      continue;
    }
    if (w.size() >= 3 && w[0] == "element" && w[1] == "face") {
      try {
        header.faces = header.faces || std::stoll(w[2]) > 0;
      } catch (...) {
        // not a count: noted below
      }
    }
    if (w.empty()) note(line_no, "empty");
    else if (w[0] == "comment" || w[0] == "obj_info") continue;
    else if (w[0] == "format" && w.size() == 3) continue;
    else if (w[0] == "element" && w.size() == 3 && w[2].find_first_not_of("0123456789") == std::string::npos) continue;
    else if (w[0] == "property" && w.size() == 3 && is_type(w[1])) continue;
    else if (w[0] == "property" && w.size() == 5 && w[1] == "list" && is_type(w[2]) && is_type(w[3])) continue;
    else note(line_no, "expected format, element, property, comment or end_header");
  }
  if (header.problem.empty()) header.problem = fmt::format("{}: the PLY header has no end_header line", path);
  return header;
}

}  // namespace

TriangleMesh read_mesh(const std::string& path) {
  check_input_file(path, "mesh file");
  if (file_extension(path) == ".ply")
    if (const PlyHeader header = scan_ply_header(path); !header.problem.empty()) throw Error(header.problem);
  Assimp::Importer importer;
  // no post-processing: assimp's steps abort the process on some malformed files (found by fuzz_mesh_ply), so
  // polygons are split and duplicate vertices joined here, every index checked
  const aiScene* scene = importer.ReadFile(path, 0);
  if (!scene) throw Error(fmt::format("{}: cannot read the mesh: {}", path, importer.GetErrorString()));
  TriangleMesh mesh;
  std::size_t n_vertices = 0;
  for (unsigned m = 0; m < scene->mNumMeshes; ++m) n_vertices += scene->mMeshes[m]->mNumVertices;
  mesh.V.resize(3, static_cast<Eigen::Index>(n_vertices));
  index_t base = 0;
  for (unsigned m = 0; m < scene->mNumMeshes; ++m) {
    const aiMesh* am = scene->mMeshes[m];
    if (am->mNumVertices > 0 && !am->mVertices) throw Error(fmt::format("{}: a mesh without its vertices", path));
    for (unsigned v = 0; v < am->mNumVertices; ++v)
      mesh.V.col(base + static_cast<index_t>(v)) = Vec3(am->mVertices[v].x, am->mVertices[v].y, am->mVertices[v].z);
    for (unsigned f = 0; f < am->mNumFaces; ++f) {
      const aiFace& face = am->mFaces[f];
      if (face.mNumIndices < 3 || !face.mIndices) continue;  // points and lines of a mixed file
      for (unsigned k = 0; k < face.mNumIndices; ++k)
        if (face.mIndices[k] >= am->mNumVertices)
          throw Error(fmt::format("{}: face {} names vertex {} of {}", path, f, face.mIndices[k], am->mNumVertices));
      // a polygon as a fan of triangles from its first vertex (the faces of mesh files are convex)
      for (unsigned k = 1; k + 1 < face.mNumIndices; ++k)
        mesh.F.push_back({base + static_cast<index_t>(face.mIndices[0]), base + static_cast<index_t>(face.mIndices[k]),
                          base + static_cast<index_t>(face.mIndices[k + 1])});
    }
    base += static_cast<index_t>(am->mNumVertices);
  }
  if (mesh.F.empty()) throw Error(fmt::format("{}: the file holds no triangle", path));
  // STL repeats every vertex per triangle: exact duplicates are joined, which the closedness check needs
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
  return scan_ply_header(path).faces;
}

}  // namespace pointhaptics
