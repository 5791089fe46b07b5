// Particle splatting in compute shaders (GL 4.3): one invocation per particle, read from the same
// buffers the sprite pass draws (renderer particle buffers bound as SSBOs), covering the same
// pixels as sphere.vert's point sprite. Needs camera.glsl and sphere_hit.glsl before it.
// Why compute at all: docs/RENDERING.md, section Speed (GH100 has almost no raster units).
layout(local_size_x = 64) in;

layout(std430, binding = 0) readonly buffer Positions { float b_pos[]; };  // x y z, tightly packed
layout(std430, binding = 1) readonly buffer Phases { uint b_phase[]; };
// Anisotropic kernels (kernels/physics/anisotropy.hpp, uploaded or copied in by the CUDA
// interop), 3 vec4 per particle: centre (world) and the radius of
// a sphere bounding the ellipsoid; the ellipsoid's matrix M (world, x inside iff
// (x - c)^T M (x - c) <= 1) as M00 M01 M02 M11, M12 M22; then 1 for a lone drop, else 0.
layout(std430, binding = 2) readonly buffer Ellipsoids { vec4 b_ell[]; };

uniform mat4 u_view, u_proj;
uniform uint u_count;            // particles in the buffers
uniform uint u_phase_mask;       // splat particles with any of these phase flags; 0 = all
uniform float u_fmax;            // max(fx, fy), pixels
uniform float u_max_point_size;  // pixels (render.max_point_size)
uniform sampler2D u_scene_depth; // window depth of the scene, full resolution
uniform bool u_aniso;            // splat b_ell's ellipsoids, not spheres of u_radius
uniform float u_drop_radius;     // a lone drop's radius, metres: the particle's own (Lone drops below)

// One particle's splat in eye space: centre c, bounding radius r; M the ellipsoid's matrix
// (anisotropic kernels), unused for a sphere (ray_sphere with u_radius); drop: a lone drop.
struct Splat {
  vec3 c;
  float r;
  mat3 M;
  bool drop;
};

// Lone drops. The splat radius u_radius (fluid_radius_scale particle radii) is larger than a
// particle so that neighbouring spheres close into one surface; a particle with too few
// neighbours for a shape has no surface to close, and drawn at u_radius it is a disc 1.5 times
// the particle's size that the depth filter then flattens. The anisotropic kernels mark such a
// particle (fewer than N_eps fluid neighbours, Yu & Turk 2013, section 4: the third vec4's z,
// kernels/physics/anisotropy.hpp). It is drawn as a drop of the particle's own radius
// (u_drop_radius), the size at which the solver lets it rest on a surface, so the bead touches
// the table it lies on instead of sinking half a radius into it. Whether the nearest splat at a
// pixel is a drop travels with its depth, in the depth's least significant mantissa bit
// (camera.glsl, with_drop_flag): one ulp of depth (1e-7 m at 1 m) is far below any depth the passes resolve, the
// atomic minimum keeps flag and depth together, and no second image has to agree with the
// first about which particle won the pixel. The later passes leave drops out of the surface
// (ssfr_filter.glsl) and shade them as beads (ssfr_composite.glsl). With spheres (no
// anisotropic kernels) there is no neighbourhood to tell, and no particle is a drop.

// This invocation's particle: groups form a 2D grid because one dimension holds at most 65535.
uint particle_index() {
  return (gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x) * gl_WorkGroupSize.x + gl_LocalInvocationID.x;
}

// Eye-space centre of particle i, with sphere.vert's rules: only masked phases, and the sphere's
// front (z - r) between the near and far planes (where the sprite vertex would be clipped).
// With anisotropic kernels the same rules hold for the ellipsoid's bounding sphere.
bool splat_shape(uint i, out Splat s) {
  if (i >= u_count) return false;
  uint ph = b_phase[i];
  if (u_phase_mask != 0u && (ph & u_phase_mask) == 0u) return false;
  if (u_aniso) {
    vec4 a = b_ell[3u * i], m = b_ell[3u * i + 1u], n = b_ell[3u * i + 2u];
    s.c = (u_view * vec4(a.xyz, 1.0)).xyz;
    s.drop = n.z > 0.5;
    s.r = s.drop ? u_drop_radius : a.w;
    mat3 Rv = mat3(u_view);  // world -> eye rotation: M_eye = Rv M Rv^T
    s.M = s.drop ? mat3(1.0 / (s.r * s.r)) : Rv * mat3(m.x, m.y, m.z, m.y, m.w, n.x, m.z, n.x, n.y) * transpose(Rv);
  } else {
    s.c = (u_view * vec4(b_pos[3u * i], b_pos[3u * i + 1u], b_pos[3u * i + 2u], 1.0)).xyz;
    s.r = u_radius;
    s.drop = false;
  }
  return s.c.z > s.r && s.c.z - s.r > u_near_far.x && s.c.z - s.r < u_near_far.y;
}

// Eye depths where the ray z * d enters and leaves the splat (ray_sphere for spheres, so that
// the sphere path stays bit for bit the raster path's).
bool ray_splat(vec3 d, Splat s, out float z_in, out float z_out) {
  if (!u_aniso) return ray_sphere(d, s.c, z_in, z_out);
  return ray_quadric(d, s.c, s.M, z_in, z_out);
}

// Image pixels (u right, v down) of sphere.vert's sprite, [lo, hi] inclusive, cut to the image:
// the sprite's window position comes from u_proj as the rasteriser gets it, its size from the
// same formula, and a point covers the pixels whose centres lie inside its square (GL 4.5 spec,
// section 14.4). Unlike a point, a splat whose centre is off screen still draws its visible part.
// r: the radius of a sphere bounding the splat.
bool splat_rect(vec3 c, float r, out ivec2 lo, out ivec2 hi) {
  vec4 clip = u_proj * vec4(c * ((c.z - r) / c.z), 1.0);
  vec2 win = (clip.xy / clip.w * 0.5 + 0.5) * u_size;
  float half_size = 0.5 * min(2.0 * r * u_fmax / (c.z - r) + 2.0, u_max_point_size);
  ivec2 w_lo = ivec2(ceil(win - half_size - 0.5)), w_hi = ivec2(ceil(win + half_size - 0.5)) - 1;
  ivec2 size = ivec2(u_size);
  w_lo = max(w_lo, ivec2(0));
  w_hi = min(w_hi, size - 1);
  // Window rows run up, image rows down.
  lo = ivec2(w_lo.x, size.y - 1 - w_hi.y);
  hi = ivec2(w_hi.x, size.y - 1 - w_lo.y);
  return all(lessThanEqual(lo, hi));
}

// Window (framebuffer) texel of image pixel p.
ivec2 window_texel(ivec2 p) { return ivec2(p.x, int(u_size.y) - 1 - p.y); }
