// Small POD math types for kernels (host and device). Eigen stays on the host side; see
// core/eigen_conv.hpp for the conversions at the boundary.
#pragma once
#include <cmath>
#include <cstdint>
#include <cstring>
#include <type_traits>

#include "core/hd.hpp"

namespace seamless {

struct vec2 {
  float x, y;
};
struct vec3 {
  float x, y, z;
};
struct vec4 {
  float x, y, z, w;
};
struct int3 {
  int x, y, z;
};
struct uchar3 {
  std::uint8_t x, y, z;
};

// vec2
SEAMLESS_HD inline vec2 operator+(vec2 a, vec2 b) { return {a.x + b.x, a.y + b.y}; }
SEAMLESS_HD inline vec2 operator-(vec2 a, vec2 b) { return {a.x - b.x, a.y - b.y}; }
SEAMLESS_HD inline vec2 operator*(vec2 a, float s) { return {a.x * s, a.y * s}; }

// vec3
SEAMLESS_HD inline vec3 operator+(vec3 a, vec3 b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
SEAMLESS_HD inline vec3 operator-(vec3 a, vec3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
SEAMLESS_HD inline vec3 operator-(vec3 a) { return {-a.x, -a.y, -a.z}; }
SEAMLESS_HD inline vec3 operator*(vec3 a, float s) { return {a.x * s, a.y * s, a.z * s}; }
SEAMLESS_HD inline vec3 operator*(float s, vec3 a) { return a * s; }
SEAMLESS_HD inline vec3 operator/(vec3 a, float s) { return {a.x / s, a.y / s, a.z / s}; }
SEAMLESS_HD inline vec3 cmul(vec3 a, vec3 b) { return {a.x * b.x, a.y * b.y, a.z * b.z}; }
SEAMLESS_HD inline vec3& operator+=(vec3& a, vec3 b) {
  a = a + b;
  return a;
}
SEAMLESS_HD inline vec3& operator-=(vec3& a, vec3 b) {
  a = a - b;
  return a;
}
SEAMLESS_HD inline vec3& operator*=(vec3& a, float s) {
  a = a * s;
  return a;
}
SEAMLESS_HD inline float dot(vec3 a, vec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
SEAMLESS_HD inline vec3 cross(vec3 a, vec3 b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
SEAMLESS_HD inline float length2(vec3 a) { return dot(a, a); }
SEAMLESS_HD inline float length(vec3 a) { return sqrtf(dot(a, a)); }
// Returns the zero vector for a zero input rather than NaN: callers test for that case.
SEAMLESS_HD inline vec3 normalize(vec3 a) {
  float l = length(a);
  return l > 0.f ? a / l : vec3{0.f, 0.f, 0.f};
}
SEAMLESS_HD inline vec3 vmin(vec3 a, vec3 b) { return {fminf(a.x, b.x), fminf(a.y, b.y), fminf(a.z, b.z)}; }
SEAMLESS_HD inline vec3 vmax(vec3 a, vec3 b) { return {fmaxf(a.x, b.x), fmaxf(a.y, b.y), fmaxf(a.z, b.z)}; }
// The bits of a float as an int and back. For non-negative floats they order like the floats,
// so integer atomic min / max can find the smallest or largest float on both backends.
SEAMLESS_HD inline std::int32_t float_bits(float f) {
#ifdef __CUDA_ARCH__
  return __float_as_int(f);
#else
  std::int32_t i;
  std::memcpy(&i, &f, sizeof i);
  return i;
#endif
}
SEAMLESS_HD inline float bits_float(std::int32_t i) {
#ifdef __CUDA_ARCH__
  return __int_as_float(i);
#else
  float f;
  std::memcpy(&f, &i, sizeof f);
  return f;
#endif
}

template <class T, class = std::enable_if_t<std::is_floating_point_v<T>>> SEAMLESS_HD inline bool is_finite(T v) {
#ifdef __CUDA_ARCH__
  return isfinite(v);
#else
  return std::isfinite(v);
#endif
}
// 1 / sqrt(v): one approximate reciprocal square root and Newton steps on the GPU (its double
// sqrt and division are long instruction sequences, felt on one-thread critical paths such as
// the ICP solve), the exact expression on the CPU; they agree to about an ulp.
SEAMLESS_HD inline double rsqrt_d(double v) {
#ifdef __CUDA_ARCH__
  return rsqrt(v);
#else
  return 1.0 / std::sqrt(v);
#endif
}
SEAMLESS_HD inline bool is_finite(vec3 a) { return is_finite(a.x) && is_finite(a.y) && is_finite(a.z); }

// int3
SEAMLESS_HD inline int3 operator+(int3 a, int3 b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
SEAMLESS_HD inline int3 operator-(int3 a, int3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
SEAMLESS_HD inline bool operator==(int3 a, int3 b) { return a.x == b.x && a.y == b.y && a.z == b.z; }
// floor(x) as an int, for any x: x is first held within +-kFloorIntRange (a NaN goes to its lower
// end), so a point projected from a depth near zero, a particle flown off to infinity or a NaN gets
// a far index that every caller's bounds test rejects, never an undefined conversion (UBSan: INT_MIN,
// then INT_MIN - 1 below). On the GPU floorf and the conversion are one instruction; on the host
// without SSE4.1 (the Debian x86-64 baseline has no roundss) floorf is a libm bit sequence of ~15
// instructions, a fifth of the CPU raycast's march. Truncation, then one down where it rounded up
// (x < 0, not an integer), gives the same integer: static_cast<float>(i) is exact, since
// |i| < 2^24 or x is already an integer there.
constexpr float kFloorIntRange = 1e9f;
SEAMLESS_HD inline int floor_int(float x) {
  x = x >= -kFloorIntRange ? (x <= kFloorIntRange ? x : kFloorIntRange) : -kFloorIntRange;
#ifdef __CUDA_ARCH__
  return static_cast<int>(floorf(x));
#else
  const int i = static_cast<int>(x);
  return i - (static_cast<float>(i) > x ? 1 : 0);
#endif
}
SEAMLESS_HD inline int3 floor_to_int(vec3 a) { return {floor_int(a.x), floor_int(a.y), floor_int(a.z)}; }
// fminf/fmaxf as a compare and select, for a b that is never NaN (a NaN a gives b, as fminf does;
// signed zeros may come out either way): GCC calls libm for fminf/fmaxf on the host (minss
// differs from them for NaN and signed zeros). On the GPU they are one instruction.
SEAMLESS_HD inline float min_of(float a, float b) {
#ifdef __CUDA_ARCH__
  return fminf(a, b);
#else
  return a < b ? a : b;
#endif
}
SEAMLESS_HD inline float max_of(float a, float b) {
#ifdef __CUDA_ARCH__
  return fmaxf(a, b);
#else
  return a > b ? a : b;
#endif
}
SEAMLESS_HD inline vec3 to_vec3(int3 a) {
  return {static_cast<float>(a.x), static_cast<float>(a.y), static_cast<float>(a.z)};
}

// vec4
SEAMLESS_HD inline vec4 operator+(vec4 a, vec4 b) { return {a.x + b.x, a.y + b.y, a.z + b.z, a.w + b.w}; }
SEAMLESS_HD inline vec4 operator*(vec4 a, float s) { return {a.x * s, a.y * s, a.z * s, a.w * s}; }
SEAMLESS_HD inline vec3 xyz(vec4 a) { return {a.x, a.y, a.z}; }

// mat3, row-major: m[r][c].
struct mat3 {
  float m[3][3];
  SEAMLESS_HD static mat3 identity() { return {{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}}; }
  SEAMLESS_HD static mat3 zero() { return {{{0, 0, 0}, {0, 0, 0}, {0, 0, 0}}}; }
  SEAMLESS_HD vec3 row(int r) const { return {m[r][0], m[r][1], m[r][2]}; }
  SEAMLESS_HD vec3 col(int c) const { return {m[0][c], m[1][c], m[2][c]}; }
};
SEAMLESS_HD inline vec3 operator*(const mat3& a, vec3 v) {
  return {dot(a.row(0), v), dot(a.row(1), v), dot(a.row(2), v)};
}
SEAMLESS_HD inline mat3 operator*(const mat3& a, const mat3& b) {
  mat3 r;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) r.m[i][j] = a.m[i][0] * b.m[0][j] + a.m[i][1] * b.m[1][j] + a.m[i][2] * b.m[2][j];
  return r;
}
SEAMLESS_HD inline mat3 operator+(const mat3& a, const mat3& b) {
  mat3 r;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) r.m[i][j] = a.m[i][j] + b.m[i][j];
  return r;
}
SEAMLESS_HD inline mat3 operator*(const mat3& a, float s) {
  mat3 r;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) r.m[i][j] = a.m[i][j] * s;
  return r;
}
SEAMLESS_HD inline mat3 transpose(const mat3& a) {
  mat3 r;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) r.m[i][j] = a.m[j][i];
  return r;
}
// a b^T
SEAMLESS_HD inline mat3 outer(vec3 a, vec3 b) {
  return {{{a.x * b.x, a.x * b.y, a.x * b.z}, {a.y * b.x, a.y * b.y, a.y * b.z}, {a.z * b.x, a.z * b.y, a.z * b.z}}};
}
SEAMLESS_HD inline float determinant(const mat3& a) { return dot(a.row(0), cross(a.row(1), a.row(2))); }

// A rigid transform x -> R x + t. Poses are named a_T_b: maps coordinates in frame b to frame a
// (world_T_camera maps camera coordinates to world coordinates).
struct SE3 {
  mat3 R;
  vec3 t;
  SEAMLESS_HD static SE3 identity() { return {mat3::identity(), {0, 0, 0}}; }
  SEAMLESS_HD vec3 operator*(vec3 p) const { return R * p + t; }
  SEAMLESS_HD vec3 rotate(vec3 v) const { return R * v; }
  SEAMLESS_HD SE3 inverse() const {
    mat3 Rt = transpose(R);
    return {Rt, -(Rt * t)};
  }
};
SEAMLESS_HD inline SE3 operator*(const SE3& a, const SE3& b) { return {a.R * b.R, a.R * b.t + a.t}; }

}  // namespace seamless
