// Kernel bodies of physics/anisotropy.hpp.
#pragma once
#include <cmath>

#include "core/sym3.hpp"
#include "kernels/physics/anisotropy.hpp"

namespace seamless::kernels {

namespace detail {

SEAMLESS_HD inline void write_ellipsoid(vec4* out, vec3 c, float bound, const mat3& M, bool lone, float offset) {
  out[0] = {c.x, c.y, c.z, bound};
  out[1] = {M.m[0][0], M.m[0][1], M.m[0][2], M.m[1][1]};
  out[2] = {M.m[1][2], M.m[2][2], lone ? 1.f : 0.f, offset};
}

}  // namespace detail

template <Executor Exec>
void Anisotropy<Exec>::pack(const Exec& ex, const vec3* x, const std::uint32_t* phase, const int* id, std::int64_t n,
                            Packed* sorted) {
  ex.for_each(n, [=] SEAMLESS_HD(std::int64_t s) {
    const int i = id[s];
    sorted[s] = Packed::of_phase(x[i], phase[i]);
  });
}

template <Executor Exec> void Anisotropy<Exec>::ellipsoids(const Exec& ex, const EllipsoidViews& V) {
  ex.for_each(V.n, [=] SEAMLESS_HD(std::int64_t s) {
    const Packed me = V.sorted[s];
    const vec3 xi = me.xyz();
    vec3 centre = xi;
    float bound = V.radius;
    mat3 M = mat3::identity() * (1.f / (V.radius * V.radius));
    bool lone = false;
    float offset = 1.f;  // not fluid, or lone: drawn on its own
    if ((me.bits() & V.fluid_mask) != 0u) {
      // Weighted moments of the fluid neighbours' offsets y = x_j - x_i, weight 1 - (d / h)^3
      // (Yu & Turk eq. 11), the particle itself included.
      const float h2 = V.h * V.h, inv_h = 1.f / V.h;
      float sw = 0.f;
      vec3 sy{0.f, 0.f, 0.f};
      sym3 syy = sym3::zero();  // symmetric: its six distinct terms only
      int neighbours = 0;
      for_each_in_radius(V.grid, V.cell_start, xi, V.h, [&](int j) {
        const Packed o = V.sorted[j];
        if ((o.bits() & V.fluid_mask) == 0u) return;
        const vec3 y = o.xyz() - xi;
        const float d2 = length2(y);
        if (d2 >= h2) return;
        const float q = sqrtf(d2) * inv_h, w = 1.f - q * q * q;
        sw += w, sy = sy + w * y, syy = syy + sym_outer(y) * w;
        neighbours += j != static_cast<int>(s) ? 1 : 0;
      });
      lone = neighbours < kMinNeighbours;
      if (!lone) {
        const vec3 mean = sy / sw;
        offset = length(mean) * inv_h;
        const sym3 C = syy * (1.f / sw) + sym_outer(mean) * -1.f;  // weighted covariance (eq. 10)
        mat3 R;
        vec3 e;
        eigen_sym3(C, R, e);
        // Axes in proportion to the standard deviations along the principal directions, none
        // below 1 / kMaxAxisRatio of the longest (eq. 12's clamp), scaled to the sphere's volume
        // so that the summed chords stay a path length in fluid (the renderer's thickness pass).
        vec3 sd{sqrtf(fmaxf(e.x, 0.f)), sqrtf(fmaxf(e.y, 0.f)), sqrtf(fmaxf(e.z, 0.f))};
        const float longest = fmaxf(sd.x, fmaxf(sd.y, sd.z));
        if (longest > 0.f) {
          const float floor_sd = longest / kMaxAxisRatio;
          sd = {fmaxf(sd.x, floor_sd), fmaxf(sd.y, floor_sd), fmaxf(sd.z, floor_sd)};
          const vec3 axes = sd * (V.radius / cbrtf(sd.x * sd.y * sd.z));
          const vec3 inv2{1.f / (axes.x * axes.x), 1.f / (axes.y * axes.y), 1.f / (axes.z * axes.z)};
          for (int a = 0; a < 3; ++a)  // M = R diag(1 / axes^2) R^T
            for (int b = 0; b < 3; ++b)
              M.m[a][b] =
                  R.m[a][0] * R.m[b][0] * inv2.x + R.m[a][1] * R.m[b][1] * inv2.y + R.m[a][2] * R.m[b][2] * inv2.z;
          bound = fmaxf(axes.x, fmaxf(axes.y, axes.z));
          centre = xi + kCentreSmoothing * mean;
        }
      }
    }
    detail::write_ellipsoid(V.ellipsoids + kEllipsoidVec4s * V.id[s], centre, bound, M, lone, offset);
  });
}

}  // namespace seamless::kernels
