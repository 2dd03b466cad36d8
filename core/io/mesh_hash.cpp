#include "core/io/mesh_hash.h"

#include <openssl/evp.h>

#include <cstring>
#include <memory>

namespace surfinspect {
namespace {

constexpr char kMagic[] = "surfinspect.mesh.v1";  // includes the trailing \0

std::string Hash(const void* v, std::size_t v_bytes, const void* t, std::size_t t_bytes) {
  static_assert(sizeof(kMagic) == 20, "magic plus its NUL");
  const uint64_t counts[2] = {v_bytes / 12, t_bytes / 12};  // x86-64 and ARM64 are little-endian
  std::unique_ptr<EVP_MD_CTX, decltype(&EVP_MD_CTX_free)> ctx(EVP_MD_CTX_new(), &EVP_MD_CTX_free);
  unsigned char digest[EVP_MAX_MD_SIZE];
  unsigned int len = 0;
  EVP_DigestInit_ex(ctx.get(), EVP_sha256(), nullptr);
  EVP_DigestUpdate(ctx.get(), kMagic, sizeof(kMagic));
  EVP_DigestUpdate(ctx.get(), counts, sizeof(counts));
  EVP_DigestUpdate(ctx.get(), v, v_bytes);
  EVP_DigestUpdate(ctx.get(), t, t_bytes);
  EVP_DigestFinal_ex(ctx.get(), digest, &len);
  static const char* hex = "0123456789abcdef";
  std::string out;
  for (unsigned i = 0; i < len; ++i) {
    out += hex[digest[i] >> 4];
    out += hex[digest[i] & 15];
  }
  return out;
}

}  // namespace

std::string MeshSha256(const TriangleMesh& mesh) {
  return Hash(mesh.vertices.data(), mesh.vertices.size() * 12, mesh.triangles.data(),
              mesh.triangles.size() * 12);
}

std::string MeshSha256(const std::string& vertex_bytes, const std::string& triangle_bytes) {
  return Hash(vertex_bytes.data(), vertex_bytes.size(), triangle_bytes.data(),
              triangle_bytes.size());
}

}  // namespace surfinspect
