#include "core/io/io_mesh.h"

#include <assimp/config.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <assimp/Exporter.hpp>
#include <assimp/Importer.hpp>
#include <fstream>

#include "absl/strings/ascii.h"
#include "absl/strings/str_cat.h"
#include "core/io/atomic_file.h"
#include "core/io/mesh_precheck.h"
#include "core/io/obj_groups.h"
#include "core/io/off_format.h"
#include "core/io/ply_format.h"
#include "core/io/ply_mesh.h"
#include "core/io/text_parse.h"
#include "core/types/status_macros.h"

namespace surfinspect {
namespace {

absl::Status Bad(const std::string& path, absl::string_view why) {
  return absl::InvalidArgumentError(absl::StrCat(path, ": ", why));
}

std::string Extension(const std::string& path) {
  const auto dot = path.rfind('.');
  return dot == std::string::npos ? "" : absl::AsciiStrToLower(path.substr(dot + 1));
}

// STL and OBJ, after mesh_precheck.h passed them: Assimp merges identical
// vertices by position alone once normals, UVs and colours are dropped (STL
// stores a face normal with every corner). An STL is imported from its
// checked bytes (`stl`), an OBJ from `path`.
absl::StatusOr<TriangleMesh> ImportWithAssimp(const std::string& path, const std::string* stl) {
  Assimp::Importer importer;
  importer.SetPropertyInteger(
      AI_CONFIG_PP_RVC_FLAGS,
      aiComponent_NORMALS | aiComponent_TANGENTS_AND_BITANGENTS | aiComponent_COLORS |
          aiComponent_TEXCOORDS | aiComponent_BONEWEIGHTS | aiComponent_ANIMATIONS |
          aiComponent_TEXTURES | aiComponent_LIGHTS | aiComponent_CAMERAS | aiComponent_MATERIALS);
  const unsigned flags = aiProcess_RemoveComponent | aiProcess_Triangulate |
                         aiProcess_JoinIdenticalVertices | aiProcess_PreTransformVertices |
                         aiProcess_ValidateDataStructure;
  const aiScene* scene = nullptr;
  try {
    scene = stl ? importer.ReadFileFromMemory(stl->data(), stl->size(), flags, "stl")
                : importer.ReadFile(path, flags);
  } catch (const std::exception& e) {
    return Bad(path, absl::StrCat("importer error: ", e.what()));
  }
  if (!scene) return Bad(path, absl::StrCat("cannot import: ", importer.GetErrorString()));
  TriangleMesh mesh;
  for (unsigned m = 0; m < scene->mNumMeshes; ++m) {
    const aiMesh* am = scene->mMeshes[m];
    const auto base = static_cast<uint32_t>(mesh.vertices.size());
    for (unsigned v = 0; v < am->mNumVertices; ++v)
      mesh.vertices.emplace_back(am->mVertices[v].x, am->mVertices[v].y, am->mVertices[v].z);
    for (unsigned f = 0; f < am->mNumFaces; ++f) {
      const aiFace& face = am->mFaces[f];
      if (face.mNumIndices != 3) continue;  // points and lines carry no surface
      mesh.triangles.push_back(
          {base + face.mIndices[0], base + face.mIndices[1], base + face.mIndices[2]});
    }
  }
  return mesh;
}

absl::StatusOr<TriangleMesh> ReadByFormat(const std::string& path, const std::string& ext,
                                          const MeshReadLimits& limits) {
  if (ext != "stl" && ext != "obj" && ext != "ply" && ext != "off")
    return Bad(path, "unknown mesh format (expected .stl, .obj, .ply or .off)");
  ASSIGN_OR_RETURN(auto bytes, ReadWholeFile(path, limits.max_file_bytes));
  if (ext == "ply") return ParsePlyMesh(bytes, limits, path);
  if (ext == "off") return ParseOff(bytes, limits, path);
  if (ext == "stl") {
    RETURN_IF_ERROR(CheckStlForAssimp(&bytes, limits, path));
    return ImportWithAssimp(path, &bytes);
  }
  RETURN_IF_ERROR(CheckObj(bytes, limits, path));
  return ImportWithAssimp(path, nullptr);
}

}  // namespace

absl::StatusOr<TriangleMesh> ReadMesh(const std::string& path, const MeshReadLimits& limits) {
  ASSIGN_OR_RETURN(auto mesh, ReadByFormat(path, Extension(path), limits));
  if (mesh.num_triangles() > limits.max_triangles)
    return absl::ResourceExhaustedError(absl::StrCat(
        path, ": ", mesh.num_triangles(), " faces exceed the limit of ", limits.max_triangles));
  if (auto st = mesh.Validate(); !st.ok()) return Bad(path, st.message());
  return mesh;
}

absl::StatusOr<MeshGroups> ReadMeshGroups(const std::string& path, const TriangleMesh& mesh,
                                          const MeshReadLimits& limits, LengthUnit file_unit) {
  if (Extension(path) != "obj") return MeshGroups{};
  ASSIGN_OR_RETURN(auto bytes, ReadWholeFile(path, limits.max_file_bytes));
  return ObjGroups(bytes, mesh, path, file_unit);
}

bool PlyDeclaresFaces(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::string head(64 * 1024, '\0');
  in.read(head.data(), static_cast<std::streamsize>(head.size()));
  head.resize(static_cast<std::size_t>(in.gcount()));
  auto h = ParsePlyHeader(head, UINT64_MAX, path);
  if (!h.ok()) return false;
  const int face = h->FindElement("face");
  return face >= 0 && h->elements[face].count > 0;
}

absl::Status WriteMesh(const std::string& path, const TriangleMesh& mesh) {
  const std::string ext = Extension(path);
  if (ext == "stl") return WriteMesh(path, mesh, MeshFormat::kStlBinary);
  if (ext == "obj") return WriteMesh(path, mesh, MeshFormat::kObj);
  if (ext == "ply") return WriteMesh(path, mesh, MeshFormat::kPlyBinary);
  return Bad(path, "unknown mesh format for writing (expected .stl, .obj or .ply)");
}

absl::Status WriteMesh(const std::string& path, const TriangleMesh& mesh, MeshFormat format) {
  if (auto st = mesh.Validate(); !st.ok()) return Bad(path, st.message());
  // aiScene owns (and deletes) everything hung on it.
  aiScene scene;
  scene.mRootNode = new aiNode();
  scene.mRootNode->mMeshes = new unsigned[1]{0};
  scene.mRootNode->mNumMeshes = 1;
  scene.mMaterials = new aiMaterial* [1] { new aiMaterial() };
  scene.mNumMaterials = 1;
  auto* am = new aiMesh();
  scene.mMeshes = new aiMesh* [1] { am };
  scene.mNumMeshes = 1;
  am->mMaterialIndex = 0;
  am->mPrimitiveTypes = aiPrimitiveType_TRIANGLE;
  am->mNumVertices = static_cast<unsigned>(mesh.vertices.size());
  am->mVertices = new aiVector3D[am->mNumVertices];
  for (unsigned v = 0; v < am->mNumVertices; ++v)
    am->mVertices[v] = aiVector3D(mesh.vertices[v].x(), mesh.vertices[v].y(), mesh.vertices[v].z());
  am->mNumFaces = static_cast<unsigned>(mesh.triangles.size());
  am->mFaces = new aiFace[am->mNumFaces];
  for (unsigned f = 0; f < am->mNumFaces; ++f) {
    am->mFaces[f].mNumIndices = 3;
    am->mFaces[f].mIndices =
        new unsigned[3]{mesh.triangles[f][0], mesh.triangles[f][1], mesh.triangles[f][2]};
  }
  const char* id = "stlb";
  switch (format) {
    case MeshFormat::kStlBinary:
      id = "stlb";
      break;
    case MeshFormat::kStlAscii:
      id = "stl";
      break;
    case MeshFormat::kObj:
      id = "objnomtl";
      break;
    case MeshFormat::kPlyBinary:
      id = "plyb";
      break;
    case MeshFormat::kPlyAscii:
      id = "ply";
      break;
  }
  return WriteFileAtomically(path, [&](const std::string& tmp) -> absl::Status {
    Assimp::Exporter exporter;
    if (exporter.Export(&scene, id, tmp) != aiReturn_SUCCESS)
      return absl::InternalError(
          absl::StrCat(path, ": export failed: ", exporter.GetErrorString()));
    return absl::OkStatus();
  });
}

}  // namespace surfinspect
