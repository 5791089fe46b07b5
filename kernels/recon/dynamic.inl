// Kernel bodies for recon/dynamic.hpp, compiled once per backend.
#include <cmath>

#include "kernels/recon/dynamic.hpp"

namespace seamless::kernels {

template <Executor Exec>
void Dynamic<Exec>::classify_dynamic(const Exec& ex, DynamicInput in, View2D<std::uint8_t> candidates) {
  const int w = in.depth.width;
  ex.for_each(in.depth.count(), [=] SEAMLESS_HD(std::int64_t i) {
    const int x = static_cast<int>(i % w), y = static_cast<int>(i / w);
    candidates(x, y) = 0;
    const float d = in.depth(x, y);
    if (!(d > 0.f)) return;
    const vec3 p = in.ref_T_cur * in.K.unproject(static_cast<float>(x), static_cast<float>(y), d);
    if (p.z <= 0.f) return;
    const vec2 uv = in.K.project(p);
    const int u0 = floor_int(uv.x + 0.5f), v0 = floor_int(uv.y + 0.5f);
    // The model planes and the nearest model surface in a small window: projective association is
    // off by the pose error (a pixel or two), which at a depth edge would otherwise pair a
    // measurement on the near side with model on the far side. A plane explains the measurement
    // when it lies within the threshold of it on either side; one the measurement lies well behind
    // is an occluder's (a mover just behind a model edge, e.g. a person behind the desk's edge),
    // which must not hide the planes it is in front of (ReFusion's residual, section III-C, taken
    // per plane of the window).
    const float threshold = dynamic_threshold(in, d);
    float front = -1e30f, nearest = 1e30f;
    bool any = false, fits = false;
    for (int dy = -in.search_radius; dy <= in.search_radius; ++dy)
      for (int dx = -in.search_radius; dx <= in.search_radius; ++dx) {
        const int u = u0 + dx, v = v0 + dy;
        if (!in.model_vertices.inside(u, v)) continue;
        const vec3 m = in.model_vertices(u, v), n = in.model_normals(u, v);
        if (!(m.z > 0.f) || length2(n) == 0.f) continue;
        any = true;
        // n faces the camera, so in front of the plane is dot(p - m, n) > 0.
        const float r = dot(p - m, n);
        fits = fits || fabsf(r) <= threshold;
        front = fmaxf(front, r);
        nearest = fminf(nearest, m.z);
      }
    if (!any) {
      if (in.undecided_without_model) candidates(x, y) = 2;
      return;
    }
    const bool residual = !fits && front > threshold;       // (a)
    const bool free_space = p.z < nearest - in.free_space;  // (b)
    candidates(x, y) = residual || free_space ? 1 : 0;
  });
}

template <Executor Exec>
void Dynamic<Exec>::views_evidence(const Exec& ex, DynamicInput in, SE3 world_T_cur, PastViews views,
                                   View2D<const std::uint8_t> prev_kept, View2D<const float> prev_depth, SE3 prev_T_cur,
                                   View2D<std::uint8_t> candidates) {
  const int w = in.depth.width;
  const bool has_prev = prev_kept.data != nullptr && prev_depth.data != nullptr;
  ex.for_each(in.depth.count(), [=] SEAMLESS_HD(std::int64_t i) {
    const int x = static_cast<int>(i % w), y = static_cast<int>(i / w);
    const std::uint8_t c = candidates(x, y);
    if (!c) return;  // a candidate or an undecided pixel has a reading
    const vec3 p_cur = in.K.unproject(static_cast<float>(x), static_cast<float>(y), in.depth(x, y));
    const ViewEvidence e = view_evidence(in, views, world_T_cur * p_cur);
    if (e == ViewEvidence::seen_through) {
      candidates(x, y) = 1;
      return;
    }
    bool continued = false;
    const vec3 p = prev_T_cur * p_cur;
    if (has_prev && p.z > 0.f) {
      const vec2 uv = in.K.project(p);
      const int u0 = floor_int(uv.x + 0.5f), v0 = floor_int(uv.y + 0.5f);
      const float threshold = dynamic_threshold(in, p.z);
      for (int dy = -in.search_radius; dy <= in.search_radius && !continued; ++dy)
        for (int dx = -in.search_radius; dx <= in.search_radius && !continued; ++dx) {
          const int u = u0 + dx, v = v0 + dy;
          continued = prev_kept.inside(u, v) && prev_kept(u, v) == 1 && fabsf(prev_depth(u, v) - p.z) <= threshold;
        }
    }
    if (c == 2) {  // undecided: masked this frame where it continues a mover, never continued itself
      candidates(x, y) = continued ? 2 : 0;
      return;
    }
    candidates(x, y) = continued ? 1 : e == ViewEvidence::none ? 2 : 0;
  });
}

template <Executor Exec>
void Dynamic<Exec>::age_dynamic(const Exec& ex, DynamicInput in, View2D<const float> prev_anchor,
                                View2D<const std::uint8_t> prev_age, SE3 prev_T_cur, int static_after,
                                View2D<std::uint8_t> candidates, View2D<std::uint8_t> age, View2D<float> anchor) {
  const int w = in.depth.width;
  const bool has_prev = prev_age.data != nullptr && prev_anchor.data != nullptr;
  const SE3 cur_T_prev = prev_T_cur.inverse();
  ex.for_each(in.depth.count(), [=] SEAMLESS_HD(std::int64_t i) {
    const int x = static_cast<int>(i % w), y = static_cast<int>(i / w);
    if (!candidates(x, y)) {
      age(x, y) = 0;
      anchor(x, y) = 0.f;
      return;
    }
    const float d = in.depth(x, y);
    int a = 1;
    float z = d;
    const vec3 p = prev_T_cur * in.K.unproject(static_cast<float>(x), static_cast<float>(y), d);
    if (has_prev && p.z > 0.f) {
      const vec2 uv = in.K.project(p);
      const int u0 = floor_int(uv.x + 0.5f), v0 = floor_int(uv.y + 0.5f);
      const float threshold = dynamic_threshold(in, d);
      for (int dy = -in.search_radius; dy <= in.search_radius; ++dy)
        for (int dx = -in.search_radius; dx <= in.search_radius; ++dx) {
          const int u = u0 + dx, v = v0 + dy;
          if (!prev_age.inside(u, v) || prev_age(u, v) == 0 || !(prev_anchor(u, v) > 0.f)) continue;
          // Where that pixel's surface was when its age began, seen from this camera.
          const vec3 q = cur_T_prev * in.K.unproject(static_cast<float>(u), static_cast<float>(v), prev_anchor(u, v));
          if (fabsf(q.z - d) <= threshold && prev_age(u, v) + 1 > a) a = prev_age(u, v) + 1, z = q.z;
        }
    }
    age(x, y) = static_cast<std::uint8_t>(a < 255 ? a : 255);
    anchor(x, y) = z;
    if (static_after > 0 && a > static_after) candidates(x, y) = 0;
  });
}

template <Executor Exec>
void Dynamic<Exec>::filter_dynamic(const Exec& ex, View2D<const std::uint8_t> candidates,
                                   View2D<const std::uint8_t> prev, View2D<const float> depth, int radius,
                                   int min_support, float max_step, View2D<std::uint8_t> kept,
                                   View2D<std::uint8_t> mask) {
  const int w = candidates.width;
  const bool has_prev = prev.data != nullptr && prev.width == candidates.width && prev.height == candidates.height;
  ex.for_each(candidates.count(), [=] SEAMLESS_HD(std::int64_t i) {
    const int x = static_cast<int>(i % w), y = static_cast<int>(i / w);
    std::uint8_t k = 0;
    if (candidates(x, y)) {
      int support = 0;
      for (int dy = -radius; dy <= radius; ++dy)
        for (int dx = -radius; dx <= radius; ++dx)
          if (candidates.inside(x + dx, y + dy) && candidates(x + dx, y + dy)) ++support;
      k = support >= min_support || (has_prev && prev(x, y)) ? candidates(x, y) : 0;
    }
    kept(x, y) = k;
  });
  ex.for_each(candidates.count(), [=] SEAMLESS_HD(std::int64_t i) {
    const int x = static_cast<int>(i % w), y = static_cast<int>(i / w);
    std::uint8_t m = kept(x, y) ? 1 : 0;
    const float d = depth(x, y);
    if (!m)
      for (int dy = -radius; dy <= radius && !m; ++dy)
        for (int dx = -radius; dx <= radius && !m; ++dx) {
          const int u = x + dx, v = y + dy;
          if (kept.inside(u, v) && kept(u, v) && (!(d > 0.f) || fabsf(depth(u, v) - d) <= max_step)) m = 1;
        }
    mask(x, y) = m;
  });
}

template <Executor Exec>
void Dynamic<Exec>::mask_vertices(const Exec& ex, View2D<const std::uint8_t> mask, int scale, View2D<vec3> vertices,
                                  View2D<vec3> normals) {
  const int w = vertices.width;
  ex.for_each(vertices.count(), [=] SEAMLESS_HD(std::int64_t i) {
    const int x = static_cast<int>(i % w), y = static_cast<int>(i / w);
    bool dynamic = false;
    for (int dy = 0; dy < scale && !dynamic; ++dy)
      for (int dx = 0; dx < scale && !dynamic; ++dx)
        if (mask.inside(x * scale + dx, y * scale + dy) && mask(x * scale + dx, y * scale + dy)) dynamic = true;
    if (!dynamic) return;
    vertices(x, y) = vec3{0.f, 0.f, 0.f};
    normals(x, y) = vec3{0.f, 0.f, 0.f};
  });
}

template <Executor Exec>
void Dynamic<Exec>::mask_depth(const Exec& ex, View2D<const std::uint8_t> mask, View2D<float> depth) {
  const int w = depth.width;
  ex.for_each(depth.count(), [=] SEAMLESS_HD(std::int64_t i) {
    const int x = static_cast<int>(i % w), y = static_cast<int>(i / w);
    if (mask(x, y)) depth(x, y) = 0.f;
  });
}

template <Executor Exec> std::int64_t Dynamic<Exec>::count_dynamic(const Exec& ex, View2D<const std::uint8_t> mask) {
  const int w = mask.width;
  return ex.transform_reduce(mask.count(), std::int64_t{0}, [=] SEAMLESS_HD(std::int64_t i) {
    return static_cast<std::int64_t>(mask(static_cast<int>(i % w), static_cast<int>(i / w)) != 0);
  });
}

template <Executor Exec, class Acc>
void DynamicSpace<Exec, Acc>::require_free_space(const Exec& ex, Acc a, View2D<const float> depth, Intrinsics K,
                                                 SE3 world_T_camera, float min_weight, bool require_seen_free,
                                                 View2D<std::uint8_t> candidates) {
  const int w = depth.width;
  ex.for_each(depth.count(), [=] SEAMLESS_HD(std::int64_t i) {
    const int x = static_cast<int>(i % w), y = static_cast<int>(i / w);
    if (!candidates(x, y)) return;  // a candidate has a reading (classify_dynamic)
    BlockCache c;
    const SpaceEvidence e = space_evidence(
        a, world_T_camera * K.unproject(static_cast<float>(x), static_cast<float>(y), depth(x, y)), min_weight, c);
    if (require_seen_free ? e != SpaceEvidence::seen_free : e == SpaceEvidence::occupied) candidates(x, y) = 0;
  });
}

}  // namespace seamless::kernels
