#include "recon/marching_cubes.hpp"

#include <algorithm>
#include <string>

#include "core/error.hpp"
#include "core/exec.hpp"
#include "core/progress.hpp"
#include "kernels/recon/tsdf.hpp"

namespace seamless {

namespace {

int edge_between(int a, int b) {
  int diff = a ^ b, axis = diff == 1 ? 0 : diff == 2 ? 1 : 2;
  int lo = std::min(a, b), j = 0, m = 0;
  for (int bit = 0; bit < 3; ++bit) {
    if (bit == axis) continue;
    if (lo & (1 << bit)) j |= 1 << m;
    ++m;
  }
  return axis * 4 + j;
}

// Corners of face (axis, side) in counter-clockwise order seen from outside the cube.
std::vector<int> face_corners(int axis, int side) {
  int u = (axis + 1) % 3, v = (axis + 2) % 3;  // (u, v, axis) is right-handed
  int base = side << axis;
  std::vector<int> c = {base, base | (1 << u), base | (1 << u) | (1 << v), base | (1 << v)};
  if (side == 0) std::reverse(c.begin(), c.end());
  return c;
}

std::vector<std::int8_t> build_table() {
  std::vector<std::int8_t> table(256 * kernels::kMcRow, -1);
  for (int cube = 1; cube < 255; ++cube) {
    auto inside = [&](int k) { return (cube >> k) & 1; };
    int next[12];
    std::fill(next, next + 12, -1);
    // On each face, each run of inside corners (walking counter-clockwise) is cut off by one
    // segment from the edge where the walk enters the run to the edge where it leaves it. A
    // crossing edge is entered on one of its two faces and left on the other, so segments chain.
    for (int axis = 0; axis < 3; ++axis)
      for (int side = 0; side < 2; ++side) {
        std::vector<int> c = face_corners(axis, side);
        for (int i = 0; i < 4; ++i) {
          if (inside(c[i]) || !inside(c[(i + 1) % 4])) continue;  // find out -> in
          int entry = edge_between(c[i], c[(i + 1) % 4]);
          int j = (i + 1) % 4;
          while (inside(c[(j + 1) % 4])) j = (j + 1) % 4;
          next[entry] = edge_between(c[j], c[(j + 1) % 4]);
        }
      }
    std::vector<int> tris;
    bool used[12] = {false};
    for (int e = 0; e < 12; ++e) {
      if (next[e] < 0 || used[e]) continue;
      std::vector<int> loop;
      for (int k = e; !used[k]; k = next[k]) {
        used[k] = true;
        loop.push_back(k);
        if (next[k] < 0) throw Error("marching cubes table: open loop (internal error)");
      }
      for (std::size_t i = 1; i + 1 < loop.size(); ++i) tris.insert(tris.end(), {loop[0], loop[i], loop[i + 1]});
    }
    if (static_cast<int>(tris.size()) > kernels::kMcRow)
      throw Error("marching cubes table: configuration with more than 5 triangles (internal error)");
    std::copy(tris.begin(), tris.end(), table.begin() + cube * kernels::kMcRow);
  }
  return table;
}

// Voxel edge key -> vertex index, open addressing with linear probing (std::unordered_map allocates
// a node a vertex: slower than the kernels on a room's millions of corners). A vertex is
// named by the ~5 triangle corners that share it, mostly close together in the walk over the
// cells, so after its first lookup its slot is in the cache.
class EdgeVertices {
 public:
  // The vertex of `key`; `fresh` (the index a new vertex takes) when the key is new.
  std::int32_t find_or_add(std::uint64_t key, std::int32_t fresh) {
    if (2 * (count_ + 1) > keys_.size()) grow();
    std::size_t s = slot(key);
    while (keys_[s] != kEmpty) {
      if (keys_[s] == key) return values_[s];
      s = (s + 1) & (keys_.size() - 1);
    }
    keys_[s] = key, values_[s] = fresh, ++count_;
    return fresh;
  }

 private:
  static constexpr std::uint64_t kEmpty = ~0ull;  // edge_key uses 62 bits: never all ones
  std::size_t slot(std::uint64_t key) const {     // Fibonacci hashing: the product's top bits
    return static_cast<std::size_t>((key * 0x9E3779B97F4A7C15ull) >> (64 - bits_));
  }
  void grow() {
    std::vector<std::uint64_t> keys = std::move(keys_);
    std::vector<std::int32_t> values = std::move(values_);
    bits_ = keys.empty() ? 10 : bits_ + 1;  // 1024 slots to start, doubled at half full
    keys_.assign(std::size_t{1} << bits_, kEmpty);
    values_.assign(keys_.size(), 0);
    count_ = 0;
    for (std::size_t i = 0; i < keys.size(); ++i)
      if (keys[i] != kEmpty) find_or_add(keys[i], values[i]);
  }
  std::vector<std::uint64_t> keys_;
  std::vector<std::int32_t> values_;
  std::size_t count_ = 0;
  int bits_ = 0;
};

template <class T> void append(std::vector<T>& to, const std::vector<T>& from) {
  to.insert(to.end(), from.begin(), from.end());
}

}  // namespace

const std::vector<std::int8_t>& marching_cubes_table() {
  static const std::vector<std::int8_t> t = build_table();
  return t;
}

template <class Acc>
Mesh marching_cubes(Device d, const Acc& a, const Buffer<int3>& blocks, std::int64_t block_count, bool progress) {
  Buffer<std::int8_t> table = Buffer<std::int8_t>::from_host(marching_cubes_table(), d);
  Mesh mesh;
  EdgeVertices index;
  constexpr std::int64_t kChunk = 8192;  // blocks per pass: bounds the scratch memory
  Progress bar("mesh", block_count, progress && block_count > kChunk, "blocks/s");
  for (std::int64_t first = 0; first < block_count; first += kChunk) {
    if (first > 0) bar.update(first, std::to_string(mesh.positions.size()) + " vertices");
    std::int64_t nb = std::min(kChunk, block_count - first);
    View<const int3> chunk{blocks.data() + first, nb};
    Buffer<std::int32_t> offsets(nb * kernels::kBlockVoxels, d);
    std::int64_t tris = with_exec(d, [&]<class E>(const E& ex) {
      return kernels::TsdfExtract<E, Acc>::mesh_count(ex, a, chunk, table.data(), offsets.view());
    });
    if (tris == 0) continue;
    Buffer<std::uint64_t> keys(3 * tris, d);
    Buffer<std::int32_t> cells(3 * tris, d);
    with_exec(d, [&]<class E>(const E& ex) {
      kernels::TsdfExtract<E, Acc>::mesh_edges(ex, a, chunk, table.data(), offsets.cview(), keys.view(), cells.view());
    });
    // Vertices are numbered in the order of the corners that first name them; only those corners
    // get a vertex computed.
    const std::vector<std::uint64_t> hk = keys.to_host();
    std::vector<std::int32_t> firsts;
    const auto known = static_cast<std::int32_t>(mesh.positions.size());
    int tri[3];
    for (std::int64_t v = 0; v < 3 * tris; ++v) {
      const auto fresh = known + static_cast<std::int32_t>(firsts.size());
      tri[v % 3] = index.find_or_add(hk[static_cast<std::size_t>(v)], fresh);
      if (tri[v % 3] == fresh) firsts.push_back(static_cast<std::int32_t>(v));
      if (v % 3 == 2) mesh.triangles.push_back({tri[0], tri[1], tri[2]});
    }
    const auto nv = static_cast<std::int64_t>(firsts.size());
    Buffer<std::int32_t> corners = Buffer<std::int32_t>::from_host(firsts, d);
    Buffer<vec3> pos(nv, d), nrm(nv, d);
    Buffer<uchar3> col(nv, d);
    with_exec(d, [&]<class E>(const E& ex) {
      kernels::TsdfExtract<E, Acc>::mesh_vertices(ex, a, chunk, table.data(), offsets.cview(), cells.cview(),
                                                  corners.cview(), pos.view(), nrm.view(), col.view());
    });
    append(mesh.positions, pos.to_host());
    append(mesh.normals, nrm.to_host());
    append(mesh.colors, col.to_host());
  }
  bar.update(block_count, std::to_string(mesh.positions.size()) + " vertices");
  return mesh;
}

template Mesh marching_cubes<kernels::HashAccess>(Device, const kernels::HashAccess&, const Buffer<int3>&, std::int64_t,
                                                  bool);
template Mesh marching_cubes<kernels::DenseAccess>(Device, const kernels::DenseAccess&, const Buffer<int3>&,
                                                   std::int64_t, bool);

}  // namespace seamless
