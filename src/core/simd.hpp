// SIMD lanes for the CPU's loops that run 8 elements at once: the physics' pair loops
// (kernels/physics/cpu_tiles.cpp, 8 particles) and the voxel hash's fusion (kernels/recon/
// tsdf_fusion_simd.cpp, a block row of 8 voxels). A vector of 8 floats (vf), a lane mask (vm), a
// vector of 8 ints (vi) and a vec3 of vectors (v3), with the operators that the SPH kernels of
// particle_math.hpp (templates over the float type) and the pair terms of the families use, so that
// one expression serves the scalar code (CUDA, and the CPU where a tile of particles cannot take
// the vector path) and 8 elements at once on the CPU.
//
// Lanes are elements, not the terms of one element's sum: lane l of a tile of 8 consecutive sorted
// particles walks its own neighbour list in list order (the CUDA loops' one lane per particle), so
// every sum is formed in the scalar order and the states stay bit-identical to the scalar loops (no
// FMA contraction: the vector code is compiled for AVX2 without FMA, and a * b + c stays two
// roundings as in the scalar code).
//
// GCC vector extensions (generic code, GCC 12 or Clang): the functions that use them are compiled
// for AVX2 on x86-64 (a `#pragma GCC target` region in their file, taken where cpu_simd() finds
// AVX2 at run time; the scalar loops otherwise), for the baseline elsewhere; everything here is
// always_inline, so it takes the caller's instruction set (the compiler turns the lane loops into
// vector instructions: the physics CPU files have -fno-math-errno). Never seen by nvcc.
#pragma once
#if !defined(__CUDACC__)
#include <cstdint>
#include <cstring>

#include "core/cpu_simd.hpp"
#include "core/math.hpp"

#define SEAMLESS_SIMD_INL __attribute__((always_inline)) inline

namespace seamless::simd {

constexpr int kWidth = 8;
typedef float f8 __attribute__((vector_size(32)));
typedef std::int32_t i8 __attribute__((vector_size(32)));
typedef float f4 __attribute__((vector_size(16)));

struct vm {
  i8 v;  // all bits set: true
};
SEAMLESS_SIMD_INL vm operator&(vm a, vm b) { return {a.v & b.v}; }
SEAMLESS_SIMD_INL vm operator|(vm a, vm b) { return {a.v | b.v}; }
SEAMLESS_SIMD_INL vm operator!(vm a) { return {~a.v}; }

struct vf {
  f8 v;
  vf() = default;
  SEAMLESS_SIMD_INL vf(f8 x) : v(x) {}
  SEAMLESS_SIMD_INL vf(float s) : v(f8{} + s) {}  // broadcast
  SEAMLESS_SIMD_INL float operator[](int l) const { return v[l]; }
};
SEAMLESS_SIMD_INL vf operator+(vf a, vf b) { return a.v + b.v; }
SEAMLESS_SIMD_INL vf operator-(vf a, vf b) { return a.v - b.v; }
SEAMLESS_SIMD_INL vf operator*(vf a, vf b) { return a.v * b.v; }
SEAMLESS_SIMD_INL vf operator/(vf a, vf b) { return a.v / b.v; }
SEAMLESS_SIMD_INL vf operator-(vf a) { return -a.v; }
SEAMLESS_SIMD_INL vm operator<(vf a, vf b) { return {a.v < b.v}; }
SEAMLESS_SIMD_INL vm operator>(vf a, vf b) { return {a.v > b.v}; }
SEAMLESS_SIMD_INL vm operator<=(vf a, vf b) { return {a.v <= b.v}; }
SEAMLESS_SIMD_INL vm operator>=(vf a, vf b) { return {a.v >= b.v}; }
SEAMLESS_SIMD_INL vf select(vm m, vf a, vf b) { return m.v ? a.v : b.v; }
SEAMLESS_SIMD_INL vm select(vm m, vm a, vm b) { return {m.v ? a.v : b.v}; }
// seamless::min_of and max_of (the host's) lane by lane, and fabsf up to the sign of a zero.
SEAMLESS_SIMD_INL vf min_of(vf a, vf b) { return select(a < b, a, b); }
SEAMLESS_SIMD_INL vf max_of(vf a, vf b) { return select(a > b, a, b); }
SEAMLESS_SIMD_INL vf abs(vf a) { return select(a < vf(0.f), -a, a); }

struct vi {
  i8 v;
  vi() = default;
  SEAMLESS_SIMD_INL vi(i8 x) : v(x) {}
  SEAMLESS_SIMD_INL vi(int s) : v(i8{} + s) {}  // broadcast
  SEAMLESS_SIMD_INL int operator[](int l) const { return v[l]; }
};
SEAMLESS_SIMD_INL vi operator+(vi a, vi b) { return a.v + b.v; }
SEAMLESS_SIMD_INL vi operator-(vi a, vi b) { return a.v - b.v; }
SEAMLESS_SIMD_INL vm operator==(vi a, vi b) { return {a.v == b.v}; }
SEAMLESS_SIMD_INL vm operator!=(vi a, vi b) { return {a.v != b.v}; }
SEAMLESS_SIMD_INL vm operator<(vi a, vi b) { return {a.v < b.v}; }
SEAMLESS_SIMD_INL vm operator>(vi a, vi b) { return {a.v > b.v}; }
SEAMLESS_SIMD_INL vm operator>=(vi a, vi b) { return {a.v >= b.v}; }
SEAMLESS_SIMD_INL vi select(vm m, vi a, vi b) { return m.v ? a.v : b.v; }
// seamless::floor_int lane by lane (truncation, then one down where that rounded up).
SEAMLESS_SIMD_INL vi floor_int(vf x) {
  // Held within +-1e9 first, as the scalar seamless::floor_int (kFloorIntRange; a NaN: -1e9).
  const f8 hi = f8{} + 1e9f, lo = f8{} - 1e9f;
  x.v = x.v >= lo ? (x.v <= hi ? x.v : hi) : lo;
  const i8 i = __builtin_convertvector(x.v, i8);
  return select(vm{__builtin_convertvector(i, f8) > x.v}, vi(i - 1), vi(i));
}
// Lane by lane (the compiler makes it one vector square root; the physics CPU files have no errno).
SEAMLESS_SIMD_INL vf sqrt(vf a) {
  vf r;
  for (int l = 0; l < kWidth; ++l) r.v[l] = __builtin_sqrtf(a.v[l]);
  return r;
}
SEAMLESS_SIMD_INL vf fsqrt(vf a) { return sqrt(a); }

// Bit l set where lane l of m is true.
// (For the tile functions only: on x86 one AVX instruction, which a function not compiled for
// AVX2 cannot inline.)
#if SEAMLESS_SIMD_X86
#pragma GCC push_options
#pragma GCC target("avx2")
SEAMLESS_SIMD_INL int bits(vm m) { return __builtin_ia32_movmskps256(reinterpret_cast<f8>(m.v)); }
// Bit k set where bit b of byte k of the 32 bytes at p is set.
SEAMLESS_SIMD_INL unsigned byte_bits(const std::uint8_t* p, int b) {
  typedef char c32 __attribute__((vector_size(32)));
  typedef long long q4 __attribute__((vector_size(32)));
  q4 v;
  std::memcpy(&v, p, sizeof v);
  return static_cast<unsigned>(__builtin_ia32_pmovmskb256(reinterpret_cast<c32>(v << (7 - b))));
}
#pragma GCC pop_options
#else
SEAMLESS_SIMD_INL unsigned byte_bits(const std::uint8_t* p, int b) {
  unsigned r = 0;
  for (int k = 0; k < 32; ++k) r |= static_cast<unsigned>(p[k] >> b & 1) << k;
  return r;
}
SEAMLESS_SIMD_INL int bits(vm m) {
  int b = 0;
  for (int l = 0; l < kWidth; ++l) b |= (m.v[l] & 1) << l;
  return b;
}
#endif

// The mask of the lanes whose bit is set in b (bits' inverse).
SEAMLESS_SIMD_INL vm from_bits(int b) {
  const i8 bit = {1, 2, 4, 8, 16, 32, 64, 128};
  return {(bit & b) != 0};
}

// Left-packing of the lanes that a mask keeps (in lane order): lane[bits] moves them to the front
// (the other lanes follow), count[bits] is how many.
struct alignas(32) PackTable {
  std::int32_t lane[256][kWidth];
  std::uint8_t count[256];
  constexpr PackTable() : lane{}, count{} {
    for (int b = 0; b < 256; ++b) {
      int c = 0;
      for (int l = 0; l < kWidth; ++l)
        if (b >> l & 1) lane[b][c++] = l;
      count[b] = static_cast<std::uint8_t>(c);
      for (int l = c; l < kWidth; ++l) lane[b][l] = 0;
    }
  }
};
inline constexpr PackTable kPack{};
SEAMLESS_SIMD_INL i8 pack_lanes(int bits) {
  i8 r;
  std::memcpy(&r, kPack.lane[bits], sizeof r);
  return r;
}
// Lane l of the result is v[idx[l]]: GCC's __builtin_shuffle with a run-time index vector; Clang
// (the fuzzing build, tests/fuzz) has no such builtin and gets the same lanes by a loop.
SEAMLESS_SIMD_INL i8 permute(i8 v, i8 idx) {
#if defined(__clang__)
  i8 r;
  for (int l = 0; l < kWidth; ++l) r[l] = v[idx[l] & (kWidth - 1)];
  return r;
#else
  return __builtin_shuffle(v, idx);
#endif
}

struct v3 {
  vf x, y, z;
};
SEAMLESS_SIMD_INL v3 operator+(v3 a, v3 b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
SEAMLESS_SIMD_INL v3 operator-(v3 a, v3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
SEAMLESS_SIMD_INL v3 operator-(v3 a) { return {-a.x, -a.y, -a.z}; }
SEAMLESS_SIMD_INL v3 operator*(v3 a, vf s) { return {a.x * s, a.y * s, a.z * s}; }
SEAMLESS_SIMD_INL v3 operator*(v3 a, float s) { return a * vf(s); }
SEAMLESS_SIMD_INL v3& operator+=(v3& a, v3 b) { return a = a + b; }
// The expressions (and so the roundings) of core/math.hpp's vec3 functions.
SEAMLESS_SIMD_INL vf dot(v3 a, v3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
SEAMLESS_SIMD_INL v3 cross(v3 a, v3 b) { return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x}; }
SEAMLESS_SIMD_INL vf length2(v3 a) { return dot(a, a); }
SEAMLESS_SIMD_INL vf length(v3 a) { return sqrt(dot(a, a)); }
SEAMLESS_SIMD_INL v3 select(vm m, v3 a, v3 b) {
  return {select(m, a.x, b.x), select(m, a.y, b.y), select(m, a.z, b.z)};
}
SEAMLESS_SIMD_INL v3 broadcast(vec3 a) { return {vf(a.x), vf(a.y), vf(a.z)}; }
SEAMLESS_SIMD_INL vec3 lane(const v3& a, int l) { return {a.x[l], a.y[l], a.z[l]}; }

// Lane l of the result: the 16-byte element e[l] of a Packed-like array (4 floats), as four
// vectors (x, y, z, w): 128-bit loads and a 4x4 transpose in each half.
SEAMLESS_SIMD_INL void load_transpose(const void* const* e, vf& x, vf& y, vf& z, vf& w) {
  f4 a[kWidth];
  for (int l = 0; l < kWidth; ++l) std::memcpy(&a[l], e[l], sizeof(f4));
  const f8 c0 = __builtin_shufflevector(a[0], a[4], 0, 1, 2, 3, 4, 5, 6, 7);
  const f8 c1 = __builtin_shufflevector(a[1], a[5], 0, 1, 2, 3, 4, 5, 6, 7);
  const f8 c2 = __builtin_shufflevector(a[2], a[6], 0, 1, 2, 3, 4, 5, 6, 7);
  const f8 c3 = __builtin_shufflevector(a[3], a[7], 0, 1, 2, 3, 4, 5, 6, 7);
  const f8 t0 = __builtin_shufflevector(c0, c1, 0, 8, 1, 9, 4, 12, 5, 13);    // x0 x1 y0 y1 | x4 x5 y4 y5
  const f8 t1 = __builtin_shufflevector(c2, c3, 0, 8, 1, 9, 4, 12, 5, 13);    // x2 x3 y2 y3 | ...
  const f8 t2 = __builtin_shufflevector(c0, c1, 2, 10, 3, 11, 6, 14, 7, 15);  // z0 z1 w0 w1 | ...
  const f8 t3 = __builtin_shufflevector(c2, c3, 2, 10, 3, 11, 6, 14, 7, 15);
  x = __builtin_shufflevector(t0, t1, 0, 1, 8, 9, 4, 5, 12, 13);
  y = __builtin_shufflevector(t0, t1, 2, 3, 10, 11, 6, 7, 14, 15);
  z = __builtin_shufflevector(t2, t3, 0, 1, 8, 9, 4, 5, 12, 13);
  w = __builtin_shufflevector(t2, t3, 2, 3, 10, 11, 6, 7, 14, 15);
}

// 8 consecutive vec3 (12 bytes each) as a v3.
SEAMLESS_SIMD_INL v3 load_v3(const vec3* a) {
  v3 r;
  for (int l = 0; l < kWidth; ++l) r.x.v[l] = a[l].x, r.y.v[l] = a[l].y, r.z.v[l] = a[l].z;
  return r;
}

}  // namespace seamless::simd
#endif
