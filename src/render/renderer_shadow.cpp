// Shadows of the virtual objects from the directional light render.light_dir (docs/RENDERING.md,
// pass "shadow"). Each frame, before the scene:
//   1. bounds: the casters' bounds in the light frame; rigid bodies from the host (a few boxes),
//      particles reduced on the GPU (shadow_bounds.comp), so the map fits the objects with no
//      read-back, on the host-upload and the CUDA-interop path alike;
//   2. rigid meshes and cloth rasterised into a depth texture, orthographic along the light;
//   3. fluid particles splatted as spheres or their ellipsoids by a compute shader (shadow_splat.comp), into images
//      cleared by another (shadow_clear.comp);
//   4. both merged into one R32F map of depths along the light (shadow_resolve.comp).
// The scene pass (Kinect image or scan mesh) and the objects then look it up (shadow.glsl).
// Only virtual objects go into the map: the real image already holds the real scene's shadows.
#include <algorithm>
#include <cfloat>
#include <cmath>
#include <cstring>
#include <numbers>

#include "core/error.hpp"
#include "core/log.hpp"
#include "core/phase.hpp"
#include "render/renderer_impl.hpp"

namespace seamless {
namespace {

constexpr int kShadowMapUnit = 6, kLightBoundsUnit = 7, kFluidShadowUnit = 8,
              kBoxesUnit = 9;             // the receivers' texture units
constexpr int kMaxOccluders = 16;         // bodies that occlude the real surfaces: rows of `occluder_boxes`
constexpr GLuint kBoundsGroup = 256;      // local_size_x of shadow_bounds.comp
constexpr GLuint kBoundsGroupsMax = 256;  // grid-stride: few atomics on 6 texels
constexpr GLuint kScreenGroup = 8;

// shadow.glsl's order_int: ints ordered like the floats, for atomic min / max of signed values.
std::int32_t order_int(float f) {
  std::int32_t b;
  std::memcpy(&b, &f, sizeof b);
  return b >= 0 ? b : b ^ 0x7fffffff;
}

// World -> light frame: rows x, y across the light, z = the direction the light travels.
mat3 light_frame(vec3 dir) {
  const vec3 z = normalize(dir);
  const vec3 helper = std::abs(z.y) < 0.9f ? vec3{0, 1, 0} : vec3{1, 0, 0};
  const vec3 x = normalize(cross(helper, z));
  const vec3 y = cross(z, x);
  return {{{x.x, x.y, x.z}, {y.x, y.y, y.z}, {z.x, z.y, z.z}}};
}

std::vector<float> cols(const mat3& R) {  // column-major for glUniformMatrix3fv
  return {R.m[0][0], R.m[1][0], R.m[2][0], R.m[0][1], R.m[1][1], R.m[2][1], R.m[0][2], R.m[1][2], R.m[2][2]};
}

}  // namespace

void Renderer::Impl::build_shadow_programs() {
  has_shadow = has_compute;  // the splat, its clear and the resolve are compute shaders
  if (!has_shadow) {
    if (p.shadows) spdlog::info("render: OpenGL {} has no compute shaders; no shadows", epoxy_gl_version() / 10.0);
    return;
  }
  auto cs = [](std::vector<std::string> f) { return ShaderStage{GL_COMPUTE_SHADER, std::move(f)}; };
  shadow_bounds_prog = Program("shadow bounds", {cs({"color.glsl", "shadow.glsl", "shadow_bounds.comp"})});
  shadow_splat_prog =
      Program("shadow splat",
              {cs({"camera.glsl", "sphere_hit.glsl", "splat.glsl", "color.glsl", "shadow.glsl", "shadow_splat.comp"})});
  shadow_clear_prog = Program("shadow clear", {cs({"shadow_clear.comp"})});
  shadow_resolve_prog = Program("shadow resolve", {cs({"color.glsl", "shadow.glsl", "shadow_resolve.comp"})});
  const ShaderStage depth_only{GL_FRAGMENT_SHADER, {"shadow_caster.frag"}};
  shadow_mesh_prog =
      Program("shadow mesh casters",
              {ShaderStage{GL_VERTEX_SHADER, {"shadow_caster.glsl", "shadow.glsl", "mesh.vert"}}, depth_only});
  shadow_cloth_prog =
      Program("shadow cloth casters",
              {ShaderStage{GL_VERTEX_SHADER, {"shadow_caster.glsl", "shadow.glsl", "cloth.vert"}}, depth_only});
  light_bounds = make_texture_2d(GL_R32I, 6, 1);
  occluder_boxes = make_texture_2d(GL_RGBA32F, 4, kMaxOccluders);
}

// Map-sized targets, (re)made when render.shadow_map_size changes.
void Renderer::Impl::make_shadow_targets() {
  const int s = p.shadow_map_size;
  if (!has_shadow || s == shadow_size) return;
  shadow_size = s;
  shadow_depth = make_texture_2d(GL_DEPTH_COMPONENT32F, s, s);
  shadow_fbo = make_framebuffer({}, shadow_depth, "shadow casters");
  shadow_bits = make_texture_2d(GL_R32UI, s, s);
  shadow_thick = make_texture_2d(GL_R32UI, s, s);
  shadow_map = make_texture_2d(GL_R32F, s, s);
  shadow_fluid = make_texture_2d(GL_RG32F, s, s);
  // Outside the maps there is no caster: the border reads as infinitely far along the light (and
  // no path in fluid).
  const float far[4] = {1e30f, 0.f, 0.f, 0.f};
  for (GLuint t : {shadow_map.get(), shadow_fluid.get()}) {
    glBindTexture(GL_TEXTURE_2D, t);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_BORDER);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_BORDER);
    glTexParameterfv(GL_TEXTURE_2D, GL_TEXTURE_BORDER_COLOR, far);
  }
  glBindTexture(GL_TEXTURE_2D, 0);
}

void Renderer::Impl::shadow_uniforms(const Program& prog) const {
  glUniform1i(prog.loc("u_shadow_on"), shadow_live);
  // A program keeps its uniforms from frame to frame: the count is set every time.
  glUniform1i(prog.loc("u_occluder_count"), shadow_live ? occluder_count : 0);
  if (!shadow_live) return;
  glActiveTexture(GL_TEXTURE0 + kShadowMapUnit);
  glBindTexture(GL_TEXTURE_2D, shadow_map);
  glActiveTexture(GL_TEXTURE0 + kLightBoundsUnit);
  glBindTexture(GL_TEXTURE_2D, light_bounds);
  glActiveTexture(GL_TEXTURE0 + kFluidShadowUnit);
  glBindTexture(GL_TEXTURE_2D, shadow_fluid);
  glActiveTexture(GL_TEXTURE0);
  glUniform1i(prog.loc("u_shadow_map"), kShadowMapUnit);
  glUniform1i(prog.loc("u_light_bounds"), kLightBoundsUnit);
  glUniform1i(prog.loc("u_fluid_shadow"), kFluidShadowUnit);
  glUniform1i(prog.loc("u_fluid_shadow_on"), fluid_shadow_live);
  glUniform1i(prog.loc("u_opaque_shadow_on"), opaque_shadow_live);
  glUniform1f(prog.loc("u_fluid_radius"), list_sphere_r);
  glUniform3f(prog.loc("u_shadow_absorption"), p.absorption.x, p.absorption.y, p.absorption.z);
  glUniformMatrix3fv(prog.loc("u_light_R"), 1, GL_FALSE, cols(light_R).data());
  glUniform1f(prog.loc("u_shadow_size"), static_cast<float>(shadow_size));
  glUniform1f(prog.loc("u_light_tan"), std::tan(0.5f * p.light_angle * std::numbers::pi_v<float> / 180.f));
  glUniform1f(prog.loc("u_shadow_strength"), p.shadow_strength);
  glActiveTexture(GL_TEXTURE0 + kBoxesUnit);
  glBindTexture(GL_TEXTURE_2D, occluder_boxes);
  glActiveTexture(GL_TEXTURE0);
  glUniform1i(prog.loc("u_boxes"), kBoxesUnit);
}

// The rigid bodies as occluders of the real surfaces (occlusion.glsl): each body's box, or its
// mesh's bounds in the body frame; the first kMaxOccluders bodies, a row of 4 texels each.
void Renderer::Impl::set_occluders(const DrawList& list) {
  occluder_count = 0;
  if (!p.show_rigid) return;
  std::vector<float> rows;
  for (const RigidDraw& r : list.rigids) {
    if (occluder_count == kMaxOccluders) break;
    const Box3 box = body_box(r);
    const vec3 centre = (box.lo + box.hi) * 0.5f, half = (box.hi - box.lo) * 0.5f;
    const SE3 box_T_world = (r.world_T_body * SE3{mat3::identity(), centre}).inverse();
    for (int i = 0; i < 3; ++i)
      rows.insert(rows.end(),
                  {box_T_world.R.m[i][0], box_T_world.R.m[i][1], box_T_world.R.m[i][2], (&box_T_world.t.x)[i]});
    rows.insert(rows.end(), {half.x, half.y, half.z, 0.f});
    ++occluder_count;
  }
  if (occluder_count == 0) return;
  glBindTexture(GL_TEXTURE_2D, occluder_boxes);
  glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, 4, occluder_count, GL_RGBA, GL_FLOAT, rows.data());
  glBindTexture(GL_TEXTURE_2D, 0);
}

namespace {
// The uniforms every program that reads the bounds needs (casters and passes; no map yet).
void light_uniforms(const Program& prog, const mat3& R, GLuint bounds, int size) {
  prog.use();
  glActiveTexture(GL_TEXTURE0 + kLightBoundsUnit);
  glBindTexture(GL_TEXTURE_2D, bounds);
  glActiveTexture(GL_TEXTURE0);
  glUniform1i(prog.loc("u_light_bounds"), kLightBoundsUnit);
  glUniformMatrix3fv(prog.loc("u_light_R"), 1, GL_FALSE, cols(R).data());
  glUniform1f(prog.loc("u_shadow_size"), static_cast<float>(size));
}
}  // namespace

void Renderer::Impl::shadow_pass(const DrawList& list, std::int64_t n) {
  shadow_live = fluid_shadow_live = opaque_shadow_live = false;
  occluder_count = 0;
  if (!p.shadows || !has_shadow) return;
  set_occluders(list);
  make_shadow_targets();
  light_R = light_frame(p.light_dir);
  // Casters: the objects drawn as meshes or as fluid spheres this frame.
  const bool rigids = p.show_rigid && !list.rigids.empty();
  bool cloth = false;
  for (const ClothDraw& c : list.cloths) cloth = cloth || (p.show_cloth && n > 0 && !c.triangles.empty());
  const bool fluid = p.show_fluid && n > 0 && fluid_count != 0;
  if (!rigids && !cloth && !fluid) return;
  // The fluid's spheres as the camera sees them: the SSFR passes' enlarged spheres, a body of
  // water that transmits (fluid_transmittance, shadow.glsl); or the debug view's opaque balls.
  const bool ssfr = p.fluid == FluidDraw::ssfr;
  const float sphere_r = list.particle_radius * (ssfr ? p.fluid_radius_scale : 1.f);
  list_sphere_r = sphere_r;

  // 1. Bounds: the rigid bodies' boxes (8 corners each) on the host, then the particles.
  float lo[3] = {FLT_MAX, FLT_MAX, FLT_MAX}, hi[3] = {-FLT_MAX, -FLT_MAX, -FLT_MAX};
  if (rigids)
    for (const RigidDraw& r : list.rigids) {
      const Box3 box = body_box(r);
      const vec3 a = box.lo, b = box.hi;
      for (int k = 0; k < 8; ++k) {
        const vec3 corner{(k & 1) ? b.x : a.x, (k & 2) ? b.y : a.y, (k & 4) ? b.z : a.z};
        const vec3 q = light_R * (r.world_T_body * corner);
        for (int i = 0; i < 3; ++i) lo[i] = std::min(lo[i], (&q.x)[i]), hi[i] = std::max(hi[i], (&q.x)[i]);
      }
    }
  const std::int32_t init[6] = {order_int(lo[0]), order_int(lo[1]), order_int(lo[2]),
                                order_int(hi[0]), order_int(hi[1]), order_int(hi[2])};
  glBindTexture(GL_TEXTURE_2D, light_bounds);
  glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
  glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, 6, 1, GL_RED_INTEGER, GL_INT, init);
  const std::uint32_t mask = (fluid ? phase::kFluid : 0u) | (cloth ? phase::kCloth : 0u);
  if (mask != 0u) {
    light_uniforms(shadow_bounds_prog, light_R, light_bounds, shadow_size);
    glUniform1ui(shadow_bounds_prog.loc("u_count"), static_cast<GLuint>(n));
    glUniform1ui(shadow_bounds_prog.loc("u_phase_mask"), mask);
    const float reach = aniso_live ? FluidEllipsoids::longest_axis() : 1.f;  // in sphere radii
    glUniform1f(shadow_bounds_prog.loc("u_pad"), std::max(reach * sphere_r, list.particle_radius));
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, part_pos);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, part_phase);
    glBindImageTexture(0, light_bounds, 0, GL_FALSE, 0, GL_READ_WRITE, GL_R32I);
    const GLuint groups =
        static_cast<GLuint>(std::clamp<std::int64_t>((n + kBoundsGroup - 1) / kBoundsGroup, 1, kBoundsGroupsMax));
    glDispatchCompute(groups, 1, 1);
    glMemoryBarrier(GL_TEXTURE_FETCH_BARRIER_BIT | GL_SHADER_IMAGE_ACCESS_BARRIER_BIT);
  }

  // 2. Meshes: nearest caster depth, no culling (a box's top face, not its bottom, must be what a
  // surface under it compares with, or the contact shadow would leak light). Without mesh casters
  // (fluid only) the depth map is neither cleared nor read: its clear cost 0.3 ms at 2048^2.
  const bool meshes = rigids || cloth;
  if (meshes) {
    glBindFramebuffer(GL_FRAMEBUFFER, shadow_fbo);
    glViewport(0, 0, shadow_size, shadow_size);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LESS);
    glDepthMask(GL_TRUE);
    glClearDepth(1.0);
    glClear(GL_DEPTH_BUFFER_BIT);
  }
  if (rigids) {
    light_uniforms(shadow_mesh_prog, light_R, light_bounds, shadow_size);
    for (const RigidDraw& r : list.rigids) {
      const Mat4 model = r.mesh ? model_matrix(r.world_T_body) : model_matrix(r.world_T_body, r.half_extents);
      glUniformMatrix4fv(shadow_mesh_prog.loc("u_model"), 1, GL_FALSE, model.data());
      (r.mesh ? body_mesh(r.mesh) : box).draw();
    }
  }
  if (cloth) {
    light_uniforms(shadow_cloth_prog, light_R, light_bounds, shadow_size);
    for (const ClothDraw& c : list.cloths) {
      if (c.triangles.empty()) continue;
      upload_cloth(c.triangles, n);
      bind_cloth(shadow_cloth_prog);
      glBindVertexArray(cloth_vao);
      glDrawElements(GL_TRIANGLES, static_cast<GLsizei>(3 * cloth_tris.size()), GL_UNSIGNED_INT, nullptr);
    }
    glBindVertexArray(0);
  }

  // 3. Fluid spheres, splatted (the images are cleared to "none" first, by shadow_clear.comp).
  const auto tiles =
      static_cast<GLuint>((shadow_size + static_cast<int>(kScreenGroup) - 1) / static_cast<int>(kScreenGroup));
  if (fluid) {
    shadow_clear_prog.use();
    glMemoryBarrier(GL_SHADER_IMAGE_ACCESS_BARRIER_BIT);  // the last frame's resolve read them
    glBindImageTexture(0, shadow_bits, 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_R32UI);
    glBindImageTexture(1, shadow_thick, 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_R32UI);
    glDispatchCompute(tiles, tiles, 1);
    const Program& sp = shadow_splat_prog;
    light_uniforms(sp, light_R, light_bounds, shadow_size);
    glUniform1f(sp.loc("u_radius"), sphere_r);
    const float s = p.fluid_radius_scale;  // path in fluid: chords over the spheres' volume fraction
    glUniform1f(sp.loc("u_thickness_scale"), ssfr ? 6.f / (std::numbers::pi_v<float> * s * s * s) : 1.f);
    glUniform1f(sp.loc("u_fixed_per_metre"), kFixedPerMetre);
    glUniform1ui(sp.loc("u_count"), static_cast<GLuint>(n));
    glUniform1ui(sp.loc("u_phase_mask"), phase::kFluid);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, part_pos);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, part_phase);
    glUniform1i(sp.loc("u_aniso"), aniso_live);
    if (aniso_live) glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 2, part_ell);
    glMemoryBarrier(GL_SHADER_IMAGE_ACCESS_BARRIER_BIT | GL_TEXTURE_UPDATE_BARRIER_BIT);
    glBindImageTexture(0, shadow_bits, 0, GL_FALSE, 0, GL_READ_WRITE, GL_R32UI);
    glBindImageTexture(1, shadow_thick, 0, GL_FALSE, 0, GL_READ_WRITE, GL_R32UI);
    const std::int64_t groups = (n + kSplatGroup - 1) / kSplatGroup;
    const auto gx = static_cast<GLuint>(std::min<std::int64_t>(groups, 65535));
    glDispatchCompute(gx, static_cast<GLuint>((groups + gx - 1) / gx), 1);
    glMemoryBarrier(GL_SHADER_IMAGE_ACCESS_BARRIER_BIT);
  }

  // 4. The opaque map and the fluid's.
  const Program& rp = shadow_resolve_prog;
  light_uniforms(rp, light_R, light_bounds, shadow_size);
  glActiveTexture(GL_TEXTURE0);
  glBindTexture(GL_TEXTURE_2D, shadow_depth);
  glUniform1i(rp.loc("u_mesh_depth"), 0);
  glUniform1i(rp.loc("u_has_mesh"), meshes);
  glUniform1i(rp.loc("u_has_splat"), fluid);
  glUniform1i(rp.loc("u_splat_opaque"), !ssfr);
  glUniform1f(rp.loc("u_splat_radius"), sphere_r);
  glUniform1f(rp.loc("u_metres_per_unit"), 1.f / kFixedPerMetre);
  glBindImageTexture(0, shadow_bits, 0, GL_FALSE, 0, GL_READ_ONLY, GL_R32UI);
  glBindImageTexture(1, shadow_thick, 0, GL_FALSE, 0, GL_READ_ONLY, GL_R32UI);
  glBindImageTexture(2, shadow_map, 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_R32F);
  glBindImageTexture(3, shadow_fluid, 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_RG32F);
  glDispatchCompute(tiles, tiles, 1);
  glMemoryBarrier(GL_TEXTURE_FETCH_BARRIER_BIT | GL_SHADER_IMAGE_ACCESS_BARRIER_BIT);
  glBindTexture(GL_TEXTURE_2D, 0);
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  glViewport(0, 0, w, h);
  shadow_live = true;
  fluid_shadow_live = fluid && ssfr;
  opaque_shadow_live = meshes || (fluid && !ssfr);
}

}  // namespace seamless
