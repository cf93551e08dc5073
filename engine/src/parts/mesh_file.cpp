// Triangle meshes read from STL (ASCII, binary) and OBJ files with Assimp (shapes.hpp: load_mesh_file). Assimp
// stays behind this file: the public headers do not name it, and phiq links it privately.
#include <assimp/Importer.hpp>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>
#include <tuple>
#include <vector>

#include "phiq/shapes.hpp"
#include "phiq/text.hpp"
#include "phiq/types.hpp"

namespace phiq {

namespace {

// The file's extension in lower case (".stl"), from which Assimp chooses its reader.
std::string lower_extension(const std::string& path) {
  std::string extension = std::filesystem::path(path).extension().string();
  for (char& c : extension) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return extension;
}

// Appends the triangles of `node` and its children to `mesh`, each mesh's vertices taken through the node's
// transformation (accumulated from the root) and `scale`; vertices at the same position become one.
void collect(const aiScene& scene, const aiNode& node, const aiMatrix4x4& parent, double scale, TriangleMesh& mesh,
             std::map<std::tuple<double, double, double>, int>& index_at) {
  const aiMatrix4x4 transform = parent * node.mTransformation;
  for (unsigned m = 0; m < node.mNumMeshes; ++m) {
    const aiMesh& part = *scene.mMeshes[node.mMeshes[m]];
    if (!(part.mPrimitiveTypes & aiPrimitiveType_TRIANGLE)) continue;  // points and lines bound nothing
    std::vector<int> index(part.mNumVertices);
    for (unsigned v = 0; v < part.mNumVertices; ++v) {
      const aiVector3D& p = part.mVertices[v];
      double placed[3];
      for (unsigned i = 0; i < 3; ++i)
        placed[i] = scale * (double{transform[i][0]} * p.x + double{transform[i][1]} * p.y +
                             double{transform[i][2]} * p.z + double{transform[i][3]});
      const auto [at, added] =
          index_at.try_emplace({placed[0], placed[1], placed[2]}, static_cast<int>(mesh.vertices.size()));
      if (added) mesh.vertices.push_back({placed[0], placed[1], placed[2]});
      index[v] = at->second;
    }
    for (unsigned f = 0; f < part.mNumFaces; ++f) {
      const aiFace& face = part.mFaces[f];
      if (face.mNumIndices != 3) continue;
      mesh.triangles.push_back({index[face.mIndices[0]], index[face.mIndices[1]], index[face.mIndices[2]]});
    }
  }
  for (unsigned c = 0; c < node.mNumChildren; ++c) collect(scene, *node.mChildren[c], transform, scale, mesh, index_at);
}

}  // namespace

TriangleMesh load_mesh_file(const std::string& path, double scale) {
  const std::string file = single_line(path);
  if (!(scale > 0.0) || !std::isfinite(scale))
    throw Error(file + ": mesh scale " + shortest(scale) + " is not a positive number");
  const std::string extension = lower_extension(path);
  if (extension != ".stl" && extension != ".obj")
    throw Error(file + ": not a mesh file phiq reads (STL or OBJ, named .stl or .obj)");
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) throw Error(file + ": cannot read: is a directory");
  if (!std::ifstream(path, std::ios::binary)) throw Error(file + ": cannot read: " + std::strerror(errno));
  Assimp::Importer importer;
  const aiScene* scene = importer.ReadFile(path, aiProcess_Triangulate | aiProcess_JoinIdenticalVertices);
  const std::string format = extension == ".stl" ? "STL" : "OBJ";
  if (scene == nullptr)
    throw Error(file + ": not a readable " + format + " file: " + single_line(importer.GetErrorString()));
  if ((scene->mFlags & AI_SCENE_FLAGS_INCOMPLETE) || scene->mRootNode == nullptr)
    throw Error(file + ": not a readable " + format + " file: it holds no complete mesh");
  TriangleMesh mesh;
  std::map<std::tuple<double, double, double>, int> index_at;
  collect(*scene, *scene->mRootNode, aiMatrix4x4{}, scale, mesh, index_at);
  if (mesh.triangles.empty()) throw Error(file + ": the " + format + " file holds no triangles");
  for (const kin3::V3& v : mesh.vertices)
    if (!std::isfinite(v.x) || !std::isfinite(v.y) || !std::isfinite(v.z))
      throw Error(file + ": the " + format + " file has a vertex that is not a finite number");
  return mesh;
}

}  // namespace phiq
