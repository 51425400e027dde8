#include "import/assimp_surface.h"

#include <assimp/Exporter.hpp>
#include <assimp/Importer.hpp>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <algorithm>
#include <cctype>
#include <cstring>
#include <stdexcept>

namespace orrery {
namespace {

std::uint32_t Le(const std::string& b, std::size_t at, int bytes) {
  std::uint32_t v = 0;
  for (int k = bytes - 1; k >= 0; --k) v = v << 8 | static_cast<unsigned char>(b[at + k]);
  return v;
}

// Total uncompressed size listed by a zip file's central directory (PKWARE APPNOTE 4.3.12,
// 4.3.16): the end-of-central-directory record within the last 65557 bytes, then one 46-byte
// header per entry. Throws for a damaged directory or zip64 sizes.
std::uint64_t ZipUncompressedBytes(const std::string& b, const std::string& source) {
  const auto fail = [&](const std::string& what) { throw std::runtime_error(source + ": zip container: " + what); };
  if (b.size() < 22) fail("too short");
  std::size_t eocd = std::string::npos;
  const std::size_t lowest = b.size() > 65557 ? b.size() - 65557 : 0;
  for (std::size_t p = b.size() - 22 + 1; p-- > lowest;)
    if (Le(b, p, 4) == 0x06054b50u) {
      eocd = p;
      break;
    }
  if (eocd == std::string::npos) fail("no end-of-central-directory record");
  const std::uint32_t entries = Le(b, eocd + 10, 2), cd_size = Le(b, eocd + 12, 4), cd_offset = Le(b, eocd + 16, 4);
  if (std::uint64_t{cd_offset} + cd_size > eocd) fail("central directory outside the file");
  std::uint64_t total = 0;
  std::size_t p = cd_offset;
  for (std::uint32_t e = 0; e < entries; ++e) {
    if (p + 46 > eocd || Le(b, p, 4) != 0x02014b50u) fail("damaged central directory entry " + std::to_string(e));
    const std::uint32_t size = Le(b, p + 24, 4);
    if (size == 0xffffffffu) fail("zip64 entries are not supported");
    total += size;
    p += 46 + Le(b, p + 28, 2) + Le(b, p + 30, 2) + Le(b, p + 32, 2);
  }
  return total;
}

std::string Lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

}  // namespace

bool AssimpReadsExtension(const std::string& extension) {
  const Assimp::Importer importer;
  return !extension.empty() && importer.IsExtensionSupported(Lower(extension));
}

std::string AssimpExtensionList() {
  const Assimp::Importer importer;
  std::string list;
  importer.GetExtensionList(list);
  return list;
}

RawSurface ReadAssimpSurface(const std::filesystem::path& path, std::uintmax_t max_bytes) {
  const std::string source = path.string();
  CheckedFileSize(path, max_bytes);
  // A zip container is checked before assimp expands it
  {
    const std::string bytes = ReadFileBounded(path, max_bytes);
    if (bytes.size() >= 4 && bytes.compare(0, 4, "PK\x03\x04") == 0) {
      const std::uint64_t expanded = ZipUncompressedBytes(bytes, source);
      if (expanded > max_bytes)
        throw std::runtime_error(source + ": zip container expands to " + std::to_string(expanded) +
                                 " bytes, more than the limit of " + std::to_string(max_bytes) + " bytes");
    }
  }
  Assimp::Importer importer;
  importer.SetPropertyInteger(AI_CONFIG_PP_RVC_FLAGS, aiComponent_NORMALS | aiComponent_TANGENTS_AND_BITANGENTS |
                                                          aiComponent_COLORS | aiComponent_TEXCOORDS |
                                                          aiComponent_BONEWEIGHTS | aiComponent_ANIMATIONS |
                                                          aiComponent_TEXTURES | aiComponent_LIGHTS |
                                                          aiComponent_CAMERAS | aiComponent_MATERIALS);
  importer.SetPropertyInteger(AI_CONFIG_PP_SBP_REMOVE, aiPrimitiveType_POINT | aiPrimitiveType_LINE);
  const aiScene* scene = importer.ReadFile(
      source, aiProcess_RemoveComponent | aiProcess_PreTransformVertices | aiProcess_Triangulate | aiProcess_SortByPType);
  if (!scene) throw std::runtime_error(source + ": assimp: " + importer.GetErrorString());

  // Meshes become regions; faces with three indices become triangles
  RawSurface raw;
  raw.format = "assimp (" + Lower(path.extension().string()) + ")";
  for (unsigned m = 0; m < scene->mNumMeshes; ++m) {
    const aiMesh* mesh = scene->mMeshes[m];
    const int first = static_cast<int>(raw.vertices.size());
    const int region = static_cast<int>(raw.region_names.size());
    raw.region_names.push_back(mesh->mName.length > 0 ? std::string(mesh->mName.C_Str()) : "mesh" + std::to_string(m));
    for (unsigned v = 0; v < mesh->mNumVertices; ++v) {
      const aiVector3D& p = mesh->mVertices[v];
      raw.vertices.emplace_back(p.x, p.y, p.z);
    }
    int skipped = 0;
    for (unsigned f = 0; f < mesh->mNumFaces; ++f) {
      const aiFace& face = mesh->mFaces[f];
      if (face.mNumIndices != 3) {
        ++skipped;
        continue;
      }
      raw.triangles.push_back({first + static_cast<int>(face.mIndices[0]), first + static_cast<int>(face.mIndices[1]),
                               first + static_cast<int>(face.mIndices[2])});
      raw.triangle_region.push_back(region);
    }
    if (skipped > 0)
      raw.notes.push_back(source + ": mesh '" + raw.region_names.back() + "': " + std::to_string(skipped) +
                          " faces that are not triangles skipped");
  }
  if (raw.triangles.empty()) throw std::runtime_error(source + ": no triangles (assimp found no surface mesh)");
  return raw;
}

void WriteAssimpSurface(const TriangleMesh& mesh, const std::filesystem::path& path, const std::string& format_id) {
  // One mesh on a child of the root node (the 3MF exporter looks at children only), one default
  // material: what every exporter expects
  aiScene scene;
  scene.mRootNode = new aiNode();
  aiNode* child = new aiNode("orrery");
  child->mParent = scene.mRootNode;
  child->mMeshes = new unsigned[1]{0};
  child->mNumMeshes = 1;
  scene.mRootNode->addChildren(1, &child);
  scene.mMaterials = new aiMaterial*[1]{new aiMaterial()};
  scene.mNumMaterials = 1;
  scene.mMeshes = new aiMesh*[1]{new aiMesh()};
  scene.mNumMeshes = 1;
  aiMesh* m = scene.mMeshes[0];
  m->mName = "orrery";
  m->mMaterialIndex = 0;
  m->mPrimitiveTypes = aiPrimitiveType_TRIANGLE;
  m->mNumVertices = static_cast<unsigned>(mesh.vertices.size());
  m->mVertices = new aiVector3D[m->mNumVertices];
  for (unsigned v = 0; v < m->mNumVertices; ++v) {
    const Vec3& p = mesh.vertices[v];
    m->mVertices[v] = aiVector3D(static_cast<ai_real>(p.x()), static_cast<ai_real>(p.y()), static_cast<ai_real>(p.z()));
  }
  m->mNumFaces = static_cast<unsigned>(mesh.triangles.size());
  m->mFaces = new aiFace[m->mNumFaces];
  for (unsigned f = 0; f < m->mNumFaces; ++f) {
    m->mFaces[f].mNumIndices = 3;
    m->mFaces[f].mIndices = new unsigned[3];
    for (int k = 0; k < 3; ++k) m->mFaces[f].mIndices[k] = static_cast<unsigned>(mesh.triangles[f][k]);
  }
  Assimp::Exporter exporter;
  if (exporter.Export(&scene, format_id, path.string()) != aiReturn_SUCCESS)
    throw std::runtime_error(path.string() + ": assimp export (" + format_id + "): " + exporter.GetErrorString());
}

}  // namespace orrery
