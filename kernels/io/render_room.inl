// Kernel bodies for io/render_room.hpp, compiled once per backend.
#include <cmath>

#include "kernels/io/render_room.hpp"
#include "kernels/scene/synthetic_room.hpp"

namespace seamless::kernels {

namespace render_detail {

// Lambert shading under one fixed light plus ambient, so that colour depends only on the surface
// (view-independent: a photometric tracker sees the same colour from every pose).
SEAMLESS_HD inline uchar3 shade(vec3 albedo, vec3 n) {
  const vec3 light = normalize(vec3{0.3f, -0.4f, 1.f});
  float s = 0.45f + 0.55f * fmaxf(dot(n, light), 0.f);
  vec3 c = albedo * s;
  auto to8 = [](float v) { return static_cast<std::uint8_t>(fminf(fmaxf(v, 0.f), 1.f) * 255.f + 0.5f); };
  return {to8(c.x), to8(c.y), to8(c.z)};
}

// True when the projector (offset by the baseline along the camera's x axis) cannot see p.
SEAMLESS_HD inline bool in_projector_shadow(vec3 p, vec3 n, vec3 projector, const movers::Scene& ms) {
  vec3 to = projector - p;
  float dist = length(to);
  vec3 o = p + n * 1e-4f;
  room::Hit h = room::room_raycast(o, to / dist, dist - 2e-4f);
  return h.t > 0.f || movers::raycast(ms, o, to / dist, dist - 2e-4f).t > 0.f;
}

}  // namespace render_detail

template <Executor Exec>
void RenderRoom<Exec>::render_room(const Exec& ex, Intrinsics K, SE3 world_T_camera, DepthNoise noise,
                                   std::uint32_t seed, std::uint32_t frame, const movers::Scene& movers,
                                   View2D<float> scratch, View2D<float> depth, View2D<uchar3> rgb,
                                   View2D<std::uint8_t> mask) {
  const int w = depth.width;
  const SE3 T = world_T_camera;
  const vec3 projector = T * vec3{noise.baseline, 0.f, 0.f};
  const movers::Scene ms = movers;  // by value into the kernel
  const bool want_mask = mask.width > 0;
  // Pass 1: exact first hit. scratch = z (> 0), -z where the sensor cannot measure it (shadow or
  // grazing incidence; edges need the neighbours and come in pass 2), 0 where the ray hits nothing.
  ex.for_each(depth.count(), [=] SEAMLESS_HD(std::int64_t i) {
    int x = static_cast<int>(i % w), y = static_cast<int>(i / w);
    vec3 dc{(x - K.cx) / K.fx, (y - K.cy) / K.fy, 1.f};
    float len = length(dc);
    vec3 dir = T.rotate(dc / len);
    room::Hit h = room::room_raycast(T.t, dir);
    const movers::Hit m = movers::raycast(ms, T.t, dir, h.t > 0.f ? h.t : 1e30f);  // only in front of the room
    if (want_mask) mask(x, y) = m.t > 0.f ? static_cast<std::uint8_t>(ms.c[m.capsule].mover) : 0;
    const float t = m.t > 0.f ? m.t : h.t;
    if (t <= 0.f) {
      scratch(x, y) = 0.f;
      rgb(x, y) = {0, 0, 0};
      return;
    }
    const vec3 normal = m.t > 0.f ? m.normal : h.normal;
    vec3 p = T.t + dir * t;
    float z = t / len;  // along the optical axis: |dc| = len for the unit-z ray
    bool lost =
        noise.enabled && (dot(normal, -dir) < noise.min_incidence_cos ||
                          (noise.projector_shadow && render_detail::in_projector_shadow(p, normal, projector, ms)));
    scratch(x, y) = lost ? -z : z;
    rgb(x, y) = render_detail::shade(m.t > 0.f ? ms.c[m.capsule].albedo : room::surface_colour(h.id, p), normal);
  });
  // Pass 2: edges, range, disparity quantisation and noise.
  const std::int64_t n_pix = depth.count();
  ex.for_each(n_pix, [=] SEAMLESS_HD(std::int64_t i) {
    int x = static_cast<int>(i % w), y = static_cast<int>(i / w);
    float s = scratch(x, y);
    if (!noise.enabled) {
      depth(x, y) = fabsf(s);
      return;
    }
    float z = s;
    for (int dy = -1; dy <= 1 && z > 0.f; ++dy)
      for (int dx = -1; dx <= 1; ++dx) {
        if (!scratch.inside(x + dx, y + dy)) continue;
        float zn = fabsf(scratch(x + dx, y + dy));
        if (zn == 0.f || fabsf(zn - z) > noise.edge_jump * z) z = 0.f;
      }
    if (z < noise.min_depth || z > noise.max_depth) z = 0.f;
    float g = noise.sigma_disparity > 0.f ? hash_gauss(seed, frame, static_cast<std::uint32_t>(i)) : 0.f;
    depth(x, y) = z > 0.f ? kinect_quantise(z, K.fx, noise, g) : 0.f;
  });
}

}  // namespace seamless::kernels
