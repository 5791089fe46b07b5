// The compute path of the fluid's sphere passes (render.fluid_splat: compute): sphere depth and
// thickness splatted by compute shaders into integer images with atomics, instead of point
// sprites through the rasteriser (docs/RENDERING.md, section Speed: GH100 has raster units on
// only a few of its SMs, compute runs on all of them). Same images as the raster path.
#include <algorithm>
#include <numbers>
#include <vector>

#include "core/error.hpp"
#include "core/phase.hpp"
#include "render/renderer_impl.hpp"

namespace seamless {
namespace {

constexpr GLuint kResolveGroup = 8;          // local_size_x/y of ssfr_resolve.comp and screen.glsl
constexpr GLuint kEmptyDepth = 0xffffffffu;  // "no fluid" in the depth-bits image: above every depth
constexpr int kDepthTile = 4;                // pixels per side of ssfr_depth_tiles.comp's tiles
// The smallest offset of the neighbours' weighted mean, in h, that makes a particle an occluder
// of the depth splat (ssfr_occluders.comp). The mean lies 0.23 h inside from a particle on a flat
// face of a lattice block and 0.07 h from one a spacing further in (h = 3 spacings): the outer
// layer alone, which on a lattice already covers every ray that crosses the face (its spheres
// cover the face's plane: 0.75 spacings of radius against 0.71 from a point of the plane to the
// nearest lattice point). The image does not depend on it, only the cost.
constexpr float kOccluderOffset = 0.15f;

}  // namespace

void Renderer::Impl::build_compute_programs() {
  auto cs = [](const char* main) {
    return ShaderStage{GL_COMPUTE_SHADER, {"camera.glsl", "sphere_hit.glsl", "splat.glsl", main}};
  };
  depth_splat_prog = Program("fluid depth splat", {cs("ssfr_depth_splat.comp")});
  occluders_prog = Program("fluid depth occluders", {cs("ssfr_occluders.comp")});
  depth_tiles_prog = Program("fluid depth tiles", {ShaderStage{GL_COMPUTE_SHADER, {"ssfr_depth_tiles.comp"}}});
  occluders = GlBuffer(new_name(glGenBuffers));
  reserve_occluders(0);
  thick_splat_prog = Program("fluid thickness splat", {cs("ssfr_thickness_splat.comp")});
  resolve_prog = Program("fluid splat resolve", {ShaderStage{GL_COMPUTE_SHADER, {"ssfr_resolve.comp"}}});
  auto screen = [](const char* name, const char* body, const char* main) {
    return Program(name, {ShaderStage{GL_COMPUTE_SHADER, {"camera.glsl", "color.glsl", "screen.glsl", body, main}}});
  };
  filter_cprog = screen("fluid filter (compute)", "ssfr_filter.glsl", "ssfr_filter.comp");
  normal_cprog = screen("fluid normals (compute)", "ssfr_normal.glsl", "ssfr_normal.comp");
  composite_cprog = screen("fluid composite (compute)", "ssfr_composite.glsl", "ssfr_composite.comp");
}

namespace {
// After a compute pass wrote images: later passes sample them, render into or blit from them,
// read them back (stage images, frames), or do image loads/atomics on them.
void after_image_writes() {
  glMemoryBarrier(GL_TEXTURE_FETCH_BARRIER_BIT | GL_FRAMEBUFFER_BARRIER_BIT | GL_TEXTURE_UPDATE_BARRIER_BIT |
                  GL_SHADER_IMAGE_ACCESS_BARRIER_BIT);
}
}  // namespace

void Renderer::Impl::dispatch_screen(int iw, int ih) {
  glDispatchCompute((static_cast<GLuint>(iw) + kResolveGroup - 1) / kResolveGroup,
                    (static_cast<GLuint>(ih) + kResolveGroup - 1) / kResolveGroup, 1);
  after_image_writes();
}

namespace {
// An R32UI texture filled with `value` (the resolve pass keeps it so after every frame).
Texture make_uint_image(int w, int h, GLuint value) {
  Texture t = make_texture_2d(GL_R32UI, w, h);
  const std::vector<GLuint> fill(static_cast<std::size_t>(w) * h, value);
  glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
  glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, w, h, GL_RED_INTEGER, GL_UNSIGNED_INT, fill.data());
  return t;
}
}  // namespace

void Renderer::Impl::make_splat_targets() {
  if (!has_compute) return;
  depth_bits = make_uint_image(w, h, kEmptyDepth);
  depth_tiles = make_texture_2d(GL_R32UI, (w + kDepthTile - 1) / kDepthTile, (h + kDepthTile - 1) / kDepthTile);
  thick_fixed = make_uint_image(tw, th, 0u);
}

// Camera, sphere and particle-buffer bindings of a splat program; the same values sphere.vert gets.
void Renderer::Impl::splat_uniforms(const Program& prog, std::int64_t n, float sphere_r, const RenderCamera& cam) {
  set_camera_uniforms(prog, cam);
  glUniform1f(prog.loc("u_radius"), sphere_r);
  // A lone drop is drawn at the particle's own radius (splat.glsl, "Lone drops").
  glUniform1f(prog.loc("u_drop_radius"), sphere_r / p.fluid_radius_scale);
  glUniform3f(prog.loc("u_up"), up.x, up.y, up.z);
  glUniform1f(prog.loc("u_fmax"), std::max(cam.K.fx, cam.K.fy));
  glUniform1ui(prog.loc("u_phase_mask"), phase::kFluid);
  glUniform1f(prog.loc("u_max_point_size"), p.max_point_size);
  glUniform1ui(prog.loc("u_count"), static_cast<GLuint>(n));
  glActiveTexture(GL_TEXTURE0);
  glBindTexture(GL_TEXTURE_2D, scene_depth);
  glUniform1i(prog.loc("u_scene_depth"), 0);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, part_pos);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, part_phase);
  glUniform1i(prog.loc("u_aniso"), aniso_live);
  if (aniso_live) glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 2, part_ell);
}

namespace {
// One invocation per particle; the groups on a 2D grid (at most 65535 along each axis).
void dispatch_particles(std::int64_t n) {
  const std::int64_t groups = (n + kSplatGroup - 1) / kSplatGroup;
  const auto gx = static_cast<GLuint>(std::min<std::int64_t>(groups, 65535));
  const auto gy = static_cast<GLuint>((groups + gx - 1) / gx);
  if (gy > 65535) throw Error("render: " + std::to_string(n) + " particles are more than one compute splat can take");
  glDispatchCompute(gx, gy, 1);
}
}  // namespace

// Integer splat image -> R32F image `out` (iw x ih), and the integer image cleared again.
void Renderer::Impl::resolve_splat(GLuint acc, GLuint out, int iw, int ih, bool depth) {
  glMemoryBarrier(GL_SHADER_IMAGE_ACCESS_BARRIER_BIT);  // the splat's atomics before these loads
  resolve_prog.use();
  glBindImageTexture(0, acc, 0, GL_FALSE, 0, GL_READ_WRITE, GL_R32UI);
  glBindImageTexture(1, out, 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_R32F);
  glUniform1i(resolve_prog.loc("u_depth_bits"), depth);
  glUniform1f(resolve_prog.loc("u_metres_per_unit"), 1.f / kFixedPerMetre);
  dispatch_screen(iw, ih);  // its barriers also order the next frame's atomics on `acc`
}

void Renderer::Impl::reserve_occluders(std::int64_t n) {
  if (n <= occluder_capacity && occluder_capacity > 0) return;
  occluder_capacity = std::max<std::int64_t>(n, std::max<std::int64_t>(2 * occluder_capacity, 64));
  glBindBuffer(GL_SHADER_STORAGE_BUFFER, occluders);
  glBufferData(GL_SHADER_STORAGE_BUFFER, (occluder_capacity + 2) * static_cast<GLsizeiptr>(sizeof(GLuint)), nullptr,
               GL_DYNAMIC_DRAW);
  const GLuint zero[2] = {0u, 0u};
  glBufferSubData(GL_SHADER_STORAGE_BUFFER, 0, sizeof(zero), zero);
  glBindBuffer(GL_SHADER_STORAGE_BUFFER, 0);
}

// SSFR 1, compute: nearest sphere depth per pixel into fluid_depth[0] (0 = no fluid). With the
// anisotropic kernels and render.fluid_occluders, in two passes: the particles at the surface,
// then the others unless hidden behind them (ssfr_depth_splat.comp); the same image.
void Renderer::Impl::fluid_depth_splat(std::int64_t n, float sphere_r, const RenderCamera& cam) {
  const bool two_passes = aniso_live && p.fluid_occluders;
  reserve_occluders(two_passes ? n : 0);
  glBindBuffer(GL_SHADER_STORAGE_BUFFER, occluders);
  const GLuint zero[2] = {0u, 0u};  // occluder count, skipped count
  glBufferSubData(GL_SHADER_STORAGE_BUFFER, 0, sizeof(zero), zero);
  glBindBuffer(GL_SHADER_STORAGE_BUFFER, 0);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 3, occluders);
  occluder_passes = two_passes;
  if (two_passes) {
    splat_uniforms(occluders_prog, n, sphere_r, cam);
    glUniform1f(occluders_prog.loc("u_occluder_offset"), kOccluderOffset);
    dispatch_particles(n);
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
  }
  splat_uniforms(depth_splat_prog, n, sphere_r, cam);
  glUniform1f(depth_splat_prog.loc("u_occluder_offset"), kOccluderOffset);
  glBindImageTexture(0, depth_bits, 0, GL_FALSE, 0, GL_READ_WRITE, GL_R32UI);
  glBindImageTexture(1, depth_tiles, 0, GL_FALSE, 0, GL_READ_ONLY, GL_R32UI);
  glUniform1i(depth_splat_prog.loc("u_pass"), two_passes ? 1 : 0);
  dispatch_particles(n);
  if (two_passes) {
    glMemoryBarrier(GL_SHADER_IMAGE_ACCESS_BARRIER_BIT);
    depth_tiles_prog.use();
    glBindImageTexture(0, depth_bits, 0, GL_FALSE, 0, GL_READ_ONLY, GL_R32UI);
    glBindImageTexture(1, depth_tiles, 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_R32UI);
    dispatch_screen((w + kDepthTile - 1) / kDepthTile, (h + kDepthTile - 1) / kDepthTile);
    depth_splat_prog.use();
    glBindImageTexture(0, depth_bits, 0, GL_FALSE, 0, GL_READ_WRITE, GL_R32UI);
    glBindImageTexture(1, depth_tiles, 0, GL_FALSE, 0, GL_READ_ONLY, GL_R32UI);
    glUniform1i(depth_splat_prog.loc("u_pass"), 2);
    dispatch_particles(n);
  }
  resolve_splat(depth_bits, fluid_depth[0], w, h, true);
}

// SSFR 2, compute: summed chords at the thickness resolution (camera `low`) into thick[0].
void Renderer::Impl::fluid_thickness_splat(std::int64_t n, float sphere_r, const RenderCamera& low) {
  splat_uniforms(thick_splat_prog, n, sphere_r, low);
  const float s = p.fluid_radius_scale;
  glUniform1f(thick_splat_prog.loc("u_thickness_scale"), 6.f / (std::numbers::pi_v<float> * s * s * s));
  glUniform1f(thick_splat_prog.loc("u_fixed_per_metre"), kFixedPerMetre);
  glBindImageTexture(0, thick_fixed, 0, GL_FALSE, 0, GL_READ_WRITE, GL_R32UI);
  dispatch_particles(n);
  resolve_splat(thick_fixed, thick[0], tw, th, false);
}

}  // namespace seamless
