#include "core/io/mesh_hash.h"

#include <openssl/evp.h>

#include <cstring>
#include <initializer_list>
#include <memory>
#include <utility>

namespace surfinspect {
namespace {

constexpr char kMagic[] = "surfinspect.mesh.v1";  // includes the trailing \0

// SHA-256 of the pieces in order, as lowercase hex.
std::string Digest(std::initializer_list<std::pair<const void*, std::size_t>> pieces) {
  std::unique_ptr<EVP_MD_CTX, decltype(&EVP_MD_CTX_free)> ctx(EVP_MD_CTX_new(), &EVP_MD_CTX_free);
  unsigned char digest[EVP_MAX_MD_SIZE];
  unsigned int len = 0;
  EVP_DigestInit_ex(ctx.get(), EVP_sha256(), nullptr);
  for (const auto& [data, bytes] : pieces) EVP_DigestUpdate(ctx.get(), data, bytes);
  EVP_DigestFinal_ex(ctx.get(), digest, &len);
  static const char* hex = "0123456789abcdef";
  std::string out;
  for (unsigned i = 0; i < len; ++i) {
    out += hex[digest[i] >> 4];
    out += hex[digest[i] & 15];
  }
  return out;
}

std::string Hash(const void* v, std::size_t v_bytes, const void* t, std::size_t t_bytes) {
  static_assert(sizeof(kMagic) == 20, "magic plus its NUL");
  const uint64_t counts[2] = {v_bytes / 12, t_bytes / 12};  // x86-64 and ARM64 are little-endian
  return Digest({{kMagic, sizeof(kMagic)}, {counts, sizeof(counts)}, {v, v_bytes}, {t, t_bytes}});
}

}  // namespace

std::string Sha256Hex(std::string_view bytes) { return Digest({{bytes.data(), bytes.size()}}); }

std::string MeshSha256(const TriangleMesh& mesh) {
  return Hash(mesh.vertices.data(), mesh.vertices.size() * 12, mesh.triangles.data(),
              mesh.triangles.size() * 12);
}

std::string MeshSha256(const std::string& vertex_bytes, const std::string& triangle_bytes) {
  return Hash(vertex_bytes.data(), vertex_bytes.size(), triangle_bytes.data(),
              triangle_bytes.size());
}

}  // namespace surfinspect
