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
uniform vec3 u_up;               // world, against gravity (Lone drops at rest below)

// One particle's splat in eye space: centre c, bounding radius r; M the ellipsoid's matrix
// (anisotropic kernels), unused for a sphere (ray_sphere with u_radius); drop: a lone drop.
struct Splat {
  vec3 c;
  float r;
  mat3 M;
  bool drop;
  bool flat_drop;  // a drop lying flat (Lone drops at rest)
  vec3 up;         // against gravity, eye space
  float top;       // a flat drop's top: its height above c (a flat drop's c is its touch-down point)
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

// Window (framebuffer) texel of image pixel p.
ivec2 window_texel(ivec2 p) { return ivec2(p.x, int(u_size.y) - 1 - p.y); }

// Lone drops at rest. A lone particle is a parcel of water of the particle's volume, V = 4/3 pi r^3.
// In the air a bead is right; lying on a surface, water of that volume is a sessile drop. Wider
// than the capillary length l_c = sqrt(gamma / (rho g)) = 2.7 mm, gravity flattens it into a
// puddle of height H = 2 l_c sin(theta / 2) whatever its volume (de Gennes, Brochard-Wyart & Quere
// 2004, "Capillarity and Wetting Phenomena", ch. 2, gravity puddles), theta the contact angle:
// 70 degrees (water on varnished wood, laminate and plastics lies between about 60 and 90), so
// H = 3.1 mm. Such a puddle is a pancake: a flat top at H and an edge about l_c wide where the
// surface turns down to the contact line. It is drawn as an oblate ellipsoid centred where the drop
// touches the surface (its lower half lies behind the surface, which hides it), semi-axis 2 H along
// up and a across, cut by the plane at height H: the top is flat out to sqrt(3)/2 a and the edge
// rises over the last 0.13 a (2.9 mm for a 1 cm particle, about l_c). The cut shape holds
// 11/12 pi a^2 H, so a = sqrt(16 r^3 / (11 H)) keeps V (a 1 cm particle: a wet spot 4.3 cm
// across). The flat top is what lets drops that touch merge: two tops at the same height are one
// surface, where two domes met in a crease and read as stacked coins. A drop narrower than l_c is
// not flattened below its radius (H at most r). It stays a drop for the filter (its cap drawn as
// splatted, so its edge keeps its slope, which a filter as wide as the cap would flatten) and is
// tagged flat for the composite, which shades it as a thin layer resting on what is under it.
// A drop rests when the surface the camera measured (the scene depth, with its unmeasured planes)
// lies where the drop touches down, q = c - r up: q and the scene's point at q's pixel lie on one
// ray, and their distance along it times the cosine between the ray and up (the height of q
// above or below the surface; the cosine taken as at least 0.1, so that a grazing view accepts at
// most ten times the tolerance along the ray) must be within a radius plus two steps of a Kinect
// v1's depth quantisation (2.85e-3 z^2 m each). The drop is then laid on that measured surface,
// not where the particle rests: the solver's particles rest on the scan's particles, a bumpy
// lattice, at heights that differ by millimetres, as much as H, and two drops that touch would
// show the step between their tops as an edge.
const float kSessileHeight = 2.0 * 2.7e-3 * 0.5736;  // 2 l_c sin(35 degrees), metres

// Whether a lone drop at eye-space centre c rests on the scene; if so, lift: how far the measured
// surface lies above its touch-down point along up (negative: below).
bool rests_on_scene(vec3 c, vec3 up, out float lift) {
  vec3 q = c - u_drop_radius * up;
  if (q.z <= u_near_far.x) return false;
  vec2 px = vec2(u_K.x * q.x / q.z + u_K.z, u_K.y * q.y / q.z + u_K.w);
  ivec2 p = ivec2(floor(px + 0.5));
  if (any(lessThan(p, ivec2(0))) || any(greaterThanEqual(p, ivec2(u_size)))) return false;
  float w = texelFetch(u_scene_depth, window_texel(p), 0).r;
  if (w >= 1.0) return false;  // no surface there
  vec3 ray = pixel_ray(px);    // q = q.z ray
  float zs = eye_depth(w);
  lift = (zs - q.z) * dot(ray, up);  // the distance along the ray times the cosine with up
  return max(abs(lift), 0.1 * abs(zs - q.z) * length(ray)) < u_drop_radius + 0.006 * zs * zs;
}

// The sessile drop's shape (above) in place of the bead's, for a lone drop s at rest, its
// touch-down point lift above or below the measured surface.
void lie_flat(inout Splat s, float lift) {
  vec3 up = s.up;
  float r = u_drop_radius, H = min(kSessileHeight, r), a = sqrt(16.0 * r * r * r / (11.0 * H));
  s.c += (lift - r) * up;
  s.r = max(a, 2.0 * H);  // bounds the whole ellipsoid, the part behind the surface included
  s.M = mat3(1.0 / (a * a)) + (1.0 / (4.0 * H * H) - 1.0 / (a * a)) * outerProduct(up, up);
  s.flat_drop = true;
  s.top = H;
}

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
    s.flat_drop = false;
    s.r = s.drop ? u_drop_radius : a.w;
    mat3 Rv = mat3(u_view);  // world -> eye rotation: M_eye = Rv M Rv^T
    s.M = s.drop ? mat3(1.0 / (s.r * s.r)) : Rv * mat3(m.x, m.y, m.z, m.y, m.w, n.x, m.z, n.x, n.y) * transpose(Rv);
    s.up = Rv * u_up;
    s.top = 0.0;
    float lift;
    if (s.drop && rests_on_scene(s.c, s.up, lift)) lie_flat(s, lift);
  } else {
    s.c = (u_view * vec4(b_pos[3u * i], b_pos[3u * i + 1u], b_pos[3u * i + 2u], 1.0)).xyz;
    s.r = u_radius;
    s.drop = false;
    s.flat_drop = false;
  }
  return s.c.z > s.r && s.c.z - s.r > u_near_far.x && s.c.z - s.r < u_near_far.y;
}

// Eye depths where the ray z * d enters and leaves the splat (ray_sphere for spheres, so that
// the sphere path stays bit for bit the raster path's).
bool ray_splat(vec3 d, Splat s, out float z_in, out float z_out) {
  if (!u_aniso) return ray_sphere(d, s.c, z_in, z_out);
  if (!ray_quadric(d, s.c, s.M, z_in, z_out)) return false;
  if (!s.flat_drop) return true;
  // A flat drop keeps the part of its ellipsoid at most s.top above c: along the ray z d the
  // height is z dot(d, up) - dot(c, up), so the plane is crossed at z_top.
  float du = dot(d, s.up), hc = dot(s.c, s.up);
  if (abs(du) < 1e-6) return -hc <= s.top;
  float z_top = (s.top + hc) / du;
  if (du < 0.0) z_in = max(z_in, z_top);  // looking down: below the plane beyond z_top
  else z_out = min(z_out, z_top);
  return z_in <= z_out && z_in > u_near_far.x;
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

