#include "core/distance/wide_bvh.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <new>

#include "absl/strings/str_cat.h"
#include "core/distance/point_triangle.h"
#include "core/types/status_macros.h"

namespace surfinspect {
namespace {

// What Embree's callbacks build: nodes and leaves in its thread-local
// memory, freed with the RTCBVH once copied into the flat layout.
struct BuildItem {
  bool leaf;
  uint32_t count;
};
struct BuildNode {
  BuildItem item;
  void* child[wide::kWidth];
};
struct BuildLeaf {
  BuildItem item;
  uint32_t* triangles;
};

void* CreateNode(RTCThreadLocalAllocator alloc, unsigned int children, void*) {
  void* mem = rtcThreadLocalAlloc(alloc, sizeof(BuildNode), alignof(BuildNode));
  return new (mem) BuildNode{{false, children}, {}};
}

void SetNodeChildren(void* node, void** children, unsigned int count, void*) {
  std::copy(children, children + count, static_cast<BuildNode*>(node)->child);
}

// The boxes are recomputed from the vertices when the tree is copied, so
// they are exact whatever the builder did with them.
void SetNodeBounds(void*, const RTCBounds**, unsigned int, void*) {}

void* CreateLeaf(RTCThreadLocalAllocator alloc, const RTCBuildPrimitive* prims, size_t n, void*) {
  void* mem = rtcThreadLocalAlloc(alloc, sizeof(BuildLeaf), alignof(BuildLeaf));
  auto* ids = static_cast<uint32_t*>(rtcThreadLocalAlloc(alloc, n * sizeof(uint32_t), 4));
  for (size_t i = 0; i < n; ++i) ids[i] = prims[i].primID;
  return new (mem) BuildLeaf{{true, static_cast<uint32_t>(n)}, ids};
}

struct Box {
  Eigen::Vector3f lo = Eigen::Vector3f::Constant(std::numeric_limits<float>::infinity());
  Eigen::Vector3f hi = Eigen::Vector3f::Constant(-std::numeric_limits<float>::infinity());
  void Extend(const Eigen::Vector3f& p) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  void Extend(const Box& b) {
    lo = lo.cwiseMin(b.lo);
    hi = hi.cwiseMax(b.hi);
  }
};

struct RtcBvh {
  RTCBVH bvh;
  ~RtcBvh() { rtcReleaseBVH(bvh); }
};

}  // namespace

// Copies Embree's tree into nodes and leaf blocks, depth first, so a
// subtree's nodes and blocks lie together in memory.
class WideBvhBuilder {
 public:
  WideBvhBuilder(WideBvh& out, const TriangleMesh& mesh, const std::vector<Eigen::Vector3d>& n,
                 const std::vector<TriangleShape>& shapes)
      : out_(out), mesh_(mesh), normals_(n), shapes_(shapes) {}

  absl::Status CopyRoot(const BuildItem* root) {
    out_.nodes_.emplace_back();
    if (root->leaf) {  // a mesh of a few triangles: one node with one leaf
      out_.nodes_[0] = EmptyNode();
      out_.nodes_[0].count = 1;
      out_.stats_.depth = 1;
      Box unused;
      return AddChild(0, 0, root, 1, unused);
    }
    return CopyNode(0, reinterpret_cast<const BuildNode*>(root), 1, nullptr);
  }

  // The blocks' lanes, in parallel blocks (each lane depends only on its
  // triangle), once the walk has placed every triangle.
  void FillBlocks() {
    const std::size_t blocks = (slots_ + wide::kLeafWidth - 1) / wide::kLeafWidth;
    lane_triangle_.resize(blocks * wide::kLeafWidth, UINT32_MAX);
    out_.blocks_.resize(blocks);
    const wide::LeafBlock empty = EmptyLeafBlock();
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, blocks, 256),
                      [&](const tbb::blocked_range<std::size_t>& r) {
                        for (std::size_t b = r.begin(); b != r.end(); ++b) {
                          out_.blocks_[b] = empty;
                          for (int lane = 0; lane < wide::kLeafWidth; ++lane) {
                            const uint32_t t = lane_triangle_[b * wide::kLeafWidth + lane];
                            if (t == UINT32_MAX) continue;
                            const Triangle& tri = mesh_.triangles[t];
                            const auto& v = mesh_.vertices;
                            FillLeafLane(out_.blocks_[b], lane, t, v[tri[0]], v[tri[1]], v[tri[2]],
                                         normals_[t], shapes_[t]);
                          }
                        }
                      });
  }

 private:
  static wide::Node EmptyNode() {
    wide::Node node;
    std::memset(&node, 0, sizeof node);
    std::fill(&node.lo[0][0], &node.lo[0][0] + 3 * wide::kWidth, INFINITY);
    std::fill(&node.hi[0][0], &node.hi[0][0] + 3 * wide::kWidth, -INFINITY);
    return node;
  }

  absl::Status CopyNode(uint32_t index, const BuildNode* node, int depth, Box* box) {
    out_.nodes_[index] = EmptyNode();
    // The search's stack holds 7 entries per level of kMaxDepth.
    if (depth > wide::kMaxDepth)
      return absl::InternalError(absl::StrCat("wide BVH: deeper than ", wide::kMaxDepth));
    out_.stats_.depth = std::max(out_.stats_.depth, depth);
    Box all;
    for (uint32_t i = 0; i < node->item.count; ++i) {
      auto st = AddChild(index, i, static_cast<const BuildItem*>(node->child[i]), depth + 1, all);
      if (!st.ok()) return st;
    }
    out_.nodes_[index].count = node->item.count;
    if (box) *box = all;
    return absl::OkStatus();
  }

  // Copies the child into the parent's slot and extends `parent_box` by its box.
  absl::Status AddChild(uint32_t parent, uint32_t slot, const BuildItem* item, int depth,
                        Box& parent_box) {
    Box box;
    if (item->leaf) {
      const auto& leaf = *reinterpret_cast<const BuildLeaf*>(item);
      // The search reads a leaf from one block.
      if (leaf.item.count == 0 || leaf.item.count > wide::kMaxLeafTriangles)
        return absl::InternalError(
            absl::StrCat("wide BVH: a leaf of ", leaf.item.count, " triangles"));
      // A leaf is read with one block's bound, at the cost of some empty lanes.
      if (slots_ % wide::kLeafWidth + leaf.item.count > wide::kLeafWidth)
        slots_ += wide::kLeafWidth - slots_ % wide::kLeafWidth;
      out_.nodes_[parent].child[slot] = slots_;
      out_.nodes_[parent].leaf_triangles[slot] = static_cast<uint8_t>(leaf.item.count);
      AddLeaf(leaf, box);
    } else {
      const auto index = static_cast<uint32_t>(out_.nodes_.size());
      out_.nodes_.emplace_back();
      auto st = CopyNode(index, reinterpret_cast<const BuildNode*>(item), depth, &box);
      if (!st.ok()) return st;
      out_.nodes_[parent].child[slot] = index;
      out_.nodes_[parent].leaf_triangles[slot] = 0;
    }
    for (int a = 0; a < 3; ++a) {
      out_.nodes_[parent].lo[a][slot] = box.lo[a];
      out_.nodes_[parent].hi[a][slot] = box.hi[a];
    }
    parent_box.Extend(box);
    return absl::OkStatus();
  }

  // Triangles go to consecutive lanes (AddChild has moved a leaf that
  // would not fit in what is left of the current block to the next one,
  // leaving the lanes between unused); FillBlocks writes them.
  void AddLeaf(const BuildLeaf& leaf, Box& box) {
    lane_triangle_.resize(slots_, UINT32_MAX);
    for (uint32_t i = 0; i < leaf.item.count; ++i) {
      const uint32_t t = leaf.triangles[i];
      lane_triangle_.push_back(t);
      ++slots_;
      for (int k = 0; k < 3; ++k) box.Extend(mesh_.vertices[mesh_.triangles[t][k]]);
    }
  }

  WideBvh& out_;
  const TriangleMesh& mesh_;
  const std::vector<Eigen::Vector3d>& normals_;
  const std::vector<TriangleShape>& shapes_;
  uint32_t slots_ = 0;                   // leaf lanes placed so far
  std::vector<uint32_t> lane_triangle_;  // per lane: its triangle, UINT32_MAX if unused
};

bool SearchIsaSupported(SearchIsa isa) {
  switch (isa) {
    case SearchIsa::kAvx2:
      return __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
    case SearchIsa::kSse2:
    case SearchIsa::kAuto:
      break;
  }
  return true;
}

SearchIsa ResolveSearchIsa(SearchIsa isa) {
  if (isa != SearchIsa::kAuto) return isa;
  return SearchIsaSupported(SearchIsa::kAvx2) ? SearchIsa::kAvx2 : SearchIsa::kSse2;
}

RTCBuildQuality EmbreeBuildQuality(BvhQuality quality) {
  switch (quality) {
    case BvhQuality::kLow:
      return RTC_BUILD_QUALITY_LOW;
    case BvhQuality::kMedium:
      return RTC_BUILD_QUALITY_MEDIUM;
    case BvhQuality::kHigh:
      break;
  }
  return RTC_BUILD_QUALITY_HIGH;
}

const char* SearchIsaName(SearchIsa isa) {
  return ResolveSearchIsa(isa) == SearchIsa::kAvx2 ? "avx2" : "sse2";
}

absl::StatusOr<WideBvh> WideBvh::Build(RTCDevice device, const TriangleMesh& mesh,
                                       const std::vector<Eigen::Vector3d>& face_normals,
                                       const std::vector<TriangleShape>& shapes,
                                       RTCBuildQuality quality, SearchIsa isa) {
  if (!SearchIsaSupported(isa))
    return absl::InvalidArgumentError(
        absl::StrCat("mesh index: this CPU cannot run the ", SearchIsaName(isa), " search"));
  WideBvh out;
  out.isa_ = ResolveSearchIsa(isa);
  const bool avx2 = out.isa_ == SearchIsa::kAvx2;
  out.search_ = avx2 ? &wide::avx2::Search : &wide::sse2::Search;
  out.visit_ = avx2 ? &wide::avx2::VisitLanes : &wide::sse2::VisitLanes;
  const std::size_t n = mesh.triangles.size();
  if (n == 0) {
    out.nodes_.push_back(wide::Node{});
    return out;
  }
  std::vector<RTCBuildPrimitive> prims(n);
  for (std::size_t t = 0; t < n; ++t) {
    Box box;
    for (int k = 0; k < 3; ++k) box.Extend(mesh.vertices[mesh.triangles[t][k]]);
    prims[t] = RTCBuildPrimitive{box.lo.x(), box.lo.y(), box.lo.z(), 0,
                                 box.hi.x(), box.hi.y(), box.hi.z(), static_cast<unsigned>(t)};
  }
  RtcBvh bvh{rtcNewBVH(device)};
  if (!bvh.bvh) return absl::InternalError("mesh index: Embree could not create a BVH");
  RTCBuildArguments args = rtcDefaultBuildArguments();
  args.byteSize = sizeof(args);
  args.buildQuality = quality;
  args.maxBranchingFactor = wide::kWidth;
  args.maxDepth = wide::kMaxDepth;
  args.sahBlockSize = wide::kMaxLeafTriangles;  // a leaf of 8 costs as much as one of 1
  args.minLeafSize = 1;
  args.maxLeafSize = wide::kMaxLeafTriangles;
  args.traversalCost = 1.0f;
  args.intersectionCost = 1.0f;
  args.bvh = bvh.bvh;
  args.primitives = prims.data();
  args.primitiveCount = n;
  args.primitiveArrayCapacity = n;
  args.createNode = &CreateNode;
  args.setNodeChildren = &SetNodeChildren;
  args.setNodeBounds = &SetNodeBounds;
  args.createLeaf = &CreateLeaf;
  const auto* root = static_cast<const BuildItem*>(rtcBuildBVH(&args));
  if (!root) return absl::InternalError("mesh index: Embree's BVH build failed");
  WideBvhBuilder builder(out, mesh, face_normals, shapes);
  RETURN_IF_ERROR(builder.CopyRoot(root));
  builder.FillBlocks();
  out.nodes_.shrink_to_fit();
  out.blocks_.shrink_to_fit();
  out.stats_.nodes = out.nodes_.size();
  out.stats_.leaf_blocks = out.blocks_.size();
  return out;
}

std::size_t WideBvh::memory_bytes() const {
  return nodes_.capacity() * sizeof(wide::Node) + blocks_.capacity() * sizeof(wide::LeafBlock);
}

}  // namespace surfinspect
