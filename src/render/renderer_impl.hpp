// Internal to src/render: GL object handles and the renderer's state, shared by renderer.cpp
// (scene, objects, frame) and renderer_fluid.cpp (screen-space fluid passes).
#pragma once
#include <epoxy/gl.h>

#include <map>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "physics/fluid_ellipsoids.hpp"
#include "render/renderer.hpp"
#include "render/shader.hpp"

namespace seamless {

// Threads per work group of splat.glsl's kernels (its local_size_x): the camera's fluid splats and
// the light's.
inline constexpr GLuint kSplatGroup = 64;
// Fixed-point path in fluid (the camera's thickness splat and the light's): units per metre of
// path. Each chord is rounded to the nearest unit, so a pixel's sum is off by at most 0.5 unit per
// sphere on its ray (2^-21 m = 0.5 um each; 10^3 spheres on one ray: 0.5 mm, against a path of
// metres). uint32 then holds 2^32 / 2^20 = 4096 m of path: a ray's path in fluid is at most its
// length inside the view volume (zfar, 30 m by default, times the ray's length factor, below 2 for
// any usual field of view), two orders of magnitude beyond a room scene.
inline constexpr float kFixedPerMetre = 1048576.f;  // 2^20

// Move-only owner of one GL name; Del is the glDelete* function for it.
template <void (*Del)(GLuint)> class GlName {
 public:
  GlName() = default;
  explicit GlName(GLuint id) : id_(id) {}
  ~GlName() {
    if (id_) Del(id_);
  }
  GlName(GlName&& o) noexcept : id_(std::exchange(o.id_, 0u)) {}
  GlName& operator=(GlName&& o) noexcept {
    if (this != &o) {
      if (id_) Del(id_);
      id_ = std::exchange(o.id_, 0u);
    }
    return *this;
  }
  GLuint get() const { return id_; }
  operator GLuint() const { return id_; }

 private:
  GLuint id_ = 0;
};

void gl_delete_texture(GLuint id);
void gl_delete_buffer(GLuint id);
void gl_delete_framebuffer(GLuint id);
void gl_delete_renderbuffer(GLuint id);
void gl_delete_vertex_array(GLuint id);
using Texture = GlName<gl_delete_texture>;
using GlBuffer = GlName<gl_delete_buffer>;
using Framebuffer = GlName<gl_delete_framebuffer>;
using Renderbuffer = GlName<gl_delete_renderbuffer>;
using VertexArray = GlName<gl_delete_vertex_array>;

// sRGB-encoded 0..1 -> linear radiance (the host side of color.glsl).
vec3 srgb_to_linear(vec3 c);

Texture make_texture_2d(GLenum internal, int w, int h, GLenum filter = GL_NEAREST);
GLuint new_name(void (*gen)(GLsizei, GLuint*));
// Framebuffer with the given colour textures (attachments 0..n-1) and optional depth texture.
Framebuffer make_framebuffer(const std::vector<GLuint>& colors, GLuint depth, const char* what);
// Reads one channel layout of a colour attachment: rows bottom to top as GL stores them.
std::vector<float> read_float(GLuint fbo, int attachment, GLenum format, int channels, int w, int h);
Image<uchar3> read_rgb8(GLuint fbo, int attachment, int w, int h);

// A triangle mesh in GL buffers: positions, normals, colours (normalised bytes), indices.
struct GlMesh {
  VertexArray vao;
  GlBuffer pos, nrm, col, idx;
  GLsizei index_count = 0;
  void upload(const std::vector<vec3>& p, const std::vector<vec3>& n, const std::vector<uchar3>& c,
              const std::vector<int3>& tris, GLenum usage);
  void draw() const;
};

// Per-pass GPU times from timestamp queries between passes, resolved at the end of a frame.
class PassTimer {
 public:
  void begin_frame();
  void mark(const char* pass);  // the pass that just ended
  // The passes of this frame: waits until the GPU has done them.
  std::vector<RenderTiming> resolve();
  // The passes of the frame before this one ({} before the second frame): by now the GPU has
  // almost always done them, so the host does not wait for this frame's.
  std::vector<RenderTiming> resolve_previous();
  ~PassTimer();

 private:
  struct Frame {
    std::vector<GLuint> queries;
    std::vector<std::string> names;
    std::size_t used = 0;
  };
  static std::vector<RenderTiming> read(const Frame& f);
  Frame frames_[2];  // this frame's queries and the last frame's
  int current_ = 0;
};

struct Renderer::Impl {
  RenderParams p;
  int w = 0, h = 0;
  std::unique_ptr<HeadlessContext> ctx;
  GlInfo info;

  Program mesh_prog, cloth_prog, particle_prog, kinect_prog;
  Program fluid_depth_prog, fluid_thick_prog, filter_prog, normal_prog, composite_prog;
  // Compute splats (render.fluid_splat: compute), built only with GL >= 4.3 (has_compute).
  bool has_compute = false;
  Program depth_splat_prog, thick_splat_prog, resolve_prog;
  // The depth splat's occluders first (render.fluid_occluders, ssfr_depth_splat.comp): their list
  // (count, skipped count, indices) and the largest depth of each tile after them.
  Program occluders_prog, depth_tiles_prog;
  GlBuffer occluders;
  std::int64_t occluder_capacity = 0;
  bool occluder_passes = false;  // the last depth splat ran in two passes
  Texture depth_tiles;
  // Anisotropic kernels: the fluid's ellipsoids (physics/fluid_ellipsoids.hpp), computed on the
  // CPU for a host DrawList that has none, or copied in by the CUDA interop.
  FluidEllipsoids cpu_shapes{Device::CPU};
  bool aniso_live = false;            // this frame's splats read part_ell
  vec3 up{0.f, 1.f, 0.f};             // this frame's DrawList::up
  bool ellipsoids_in_buffer = false;  // part_ell holds the particles' ellipsoids (last upload, or the interop)
  Program filter_cprog, normal_cprog, composite_cprog;  // the full-screen passes as compute
  VertexArray empty_vao;

  // Framebuffer-sized targets (re-made by resize).
  Texture scene_color, scene_depth;
  Framebuffer scene_fbo;
  Texture final_color, reflect_color, refract_color;
  Framebuffer final_fbo;
  Texture fluid_depth[2], thick[2], normals;
  Renderbuffer fluid_zbuf, thick_zbuf;
  // Integer images the compute splats accumulate into (depth bits at w x h, fixed-point
  // thickness at tw x th); the resolve pass clears them again after reading.
  Texture depth_bits, thick_fixed;
  int tw = 0, th = 0;  // thickness targets: the framebuffer over render.thickness_downsample
  Framebuffer fluid_depth_fbo, fluid_filter_fbo[2], thick_fbo[2], normal_fbo;
  bool last_has_fluid = false;
  int last_fluid_read = 0;  // which fluid_depth[] holds the filtered depth
  int last_thick_read = 0;

  // Scene.
  GlMesh scene;
  bool has_scene = false;
  vec3 scene_lo{0, 0, 0}, scene_hi{0, 0, 0};
  Texture cube;
  bool has_cube = false;
  Texture kin_rgb, kin_depth;
  GlBuffer kin_pbo[2];  // their uploads' pixel buffers (upload_texture)
  Intrinsics kin_K;
  PixelRect kin_region;             // where the image holds colour; the frame shows it cut to the framebuffer's aspect
  vec3 kin_mean{0.5f, 0.5f, 0.5f};  // the image's mean colour, linear
  SE3 kin_pose = SE3::identity();
  bool has_kinect = false;
  std::vector<vec4> kin_planes;  // set_unmeasured_planes

  // Objects.
  GlMesh box;
  // Cloth topology (particle ids) for cloth.vert: indices, and each vertex's ring of triangles.
  std::vector<int3> cloth_tris;
  int cloth_first = 0;
  VertexArray cloth_vao;
  GlBuffer cloth_idx, cloth_ring_off, cloth_ring, cloth_uv;
  Texture pos_tbo, ring_off_tbo, ring_tbo, uv_tbo;
  // Rigid body meshes, uploaded once each; an entry whose owner has gone is dropped.
  std::map<const BodyMesh*, std::pair<std::weak_ptr<const BodyMesh>, GlMesh>> body_meshes;
  VertexArray part_vao;
  GlBuffer part_pos, part_phase;
  GlBuffer part_ell;  // FluidEllipsoids::kVec4s vec4 per particle (the anisotropic kernels)
  std::int64_t part_capacity = 0;
  std::int64_t fluid_count = -1;  // fluid particles of the last upload; -1: unknown (device data)

  // Shadows of the virtual objects (renderer_shadow.cpp): built when the context has compute
  // shaders and glClearTexImage (GL 4.4 or ARB_clear_texture).
  bool has_shadow = false;
  Program shadow_bounds_prog, shadow_clear_prog, shadow_splat_prog, shadow_resolve_prog, shadow_mesh_prog,
      shadow_cloth_prog;
  Texture light_bounds;               // 6 x 1 R32I: casters' bounds in the light frame (shadow.glsl)
  Texture shadow_depth, shadow_map;   // rasterised casters' depth, the opaque map
  Texture shadow_bits, shadow_thick;  // fluid splat: front depth bits, fixed-point path in fluid
  Texture shadow_fluid;               // RG32F: fluid front depth and path, in the splat's grid
  bool fluid_shadow_live = false;     // this frame's fluid transmits into the map
  bool opaque_shadow_live = false;    // this frame has opaque casters (meshes, or particles drawn as spheres)
  float list_sphere_r = 0.f;          // this frame's fluid sphere radius (its splat level)
  Framebuffer shadow_fbo;
  int shadow_size = 0;
  mat3 light_R = mat3::identity();  // world -> light frame
  bool shadow_live = false;         // this frame's receivers read a map
  // This frame's rigid bodies as boxes for the real surfaces' contact occlusion (occlusion.glsl):
  // how many, and their rows (world -> box frame, half extents) in a 4 x kMaxOccluders texture.
  int occluder_count = 0;
  Texture occluder_boxes;
  void set_occluders(const DrawList& list);

  std::vector<StageImage> stages;
  std::vector<RenderTiming> timings;
  PassTimer timer;

  void build_programs();
  void make_targets();
  void make_box();
  void upload_particles(const DrawList& list);
  void draw_frame(const DrawList& list, std::int64_t n, const RenderCamera& cam);
  void draw_scene(const RenderCamera& cam);
  void draw_objects(const DrawList& list, std::int64_t n, const RenderCamera& cam);
  void draw_mesh(const GlMesh& m, const RenderCamera& cam, const Mat4& model, bool vertex_color, vec3 tint, bool lit,
                 bool two_sided = false);
  void upload_cloth(const std::vector<int3>& tris, std::int64_t n);
  void draw_cloth(const RenderCamera& cam);
  const GlMesh& body_mesh(const std::shared_ptr<const BodyMesh>& m);
  void draw_spheres(const Program& prog, std::int64_t n, std::uint32_t mask, float radius, const RenderCamera& cam);
  void render_cube_map();
  // renderer_fluid.cpp
  bool draw_fluid(std::int64_t n, float radius, const RenderCamera& cam);
  void copy_scene_depth(GLuint dst, int dw, int dh);
  void fluid_depth_pass(std::int64_t n, float sphere_r, const RenderCamera& cam);
  void fluid_thickness_pass(std::int64_t n, float sphere_r, float radius, const RenderCamera& cam);
  void fluid_filter_passes(float radius, const RenderCamera& cam);
  // One axis of the filter from texture src into texture dst (iw x ih; dst_fbo renders to it).
  void filter_pass(GLuint src, GLuint dst, GLuint dst_fbo, int dx, int dy, int iw, int ih);
  const Program& filter_program() const { return use_compute_splat() ? filter_cprog : filter_prog; }
  void normals_pass(const RenderCamera& cam);
  void composite_pass(const RenderCamera& cam, float contact);
  void thickness_blur(const RenderCamera& low, float radius);
  // renderer_splat.cpp: the compute path of SSFR 1 and 2.
  bool use_compute_splat() const { return has_compute && p.fluid_splat == FluidSplat::compute; }
  void build_compute_programs();
  void make_splat_targets();
  void splat_uniforms(const Program& prog, std::int64_t n, float sphere_r, const RenderCamera& cam);
  void resolve_splat(GLuint acc, GLuint out, int iw, int ih, bool depth_bits);
  void dispatch_screen(int iw, int ih);  // 8 x 8 tiles over iw x ih, then the barriers
  void fluid_depth_splat(std::int64_t n, float sphere_r, const RenderCamera& cam);
  void reserve_occluders(std::int64_t n);
  void upload_ellipsoids(const DrawList& list, std::int64_t n);
  std::optional<Renderer::EllipsoidSizes> ellipsoid_sizes(float radius) const;
  void fluid_thickness_splat(std::int64_t n, float sphere_r, const RenderCamera& low);
  void capture_stages();
  // renderer_shadow.cpp
  void build_shadow_programs();
  void make_shadow_targets();
  void shadow_pass(const DrawList& list, std::int64_t n);
  void shadow_uniforms(const Program& prog) const;  // the receivers' (shadow.glsl)
  void bind_cloth(const Program& prog);
  void set_camera_uniforms(const Program& prog, const RenderCamera& cam) const;
  vec3 light_eye(const RenderCamera& cam) const;
};

}  // namespace seamless
