// Screen-space fluid rendering (van der Laan, Green, Sainz 2009), the reflection cube map and the
// stage images (the dissertation's Figure 4.5).
#include <algorithm>
#include <cmath>
#include <numbers>

#include "core/error.hpp"
#include "core/phase.hpp"
#include "render/renderer_impl.hpp"

namespace seamless {
namespace {

// GL cube map faces +X, -X, +Y, -Y, +Z, -Z as cameras (x right, y down, z forward): the face's
// s coordinate grows along camera x and its t coordinate against camera y (GL 4.5 spec, table
// 8.19: e.g. +X has s_c = -r_z, t_c = -r_y), so rendering with these fills the face as sampled.
constexpr float kFaceAxes[6][3][3] = {{{0, 0, -1}, {0, 1, 0}, {1, 0, 0}}, {{0, 0, 1}, {0, 1, 0}, {-1, 0, 0}},
                                      {{1, 0, 0}, {0, 0, -1}, {0, 1, 0}}, {{1, 0, 0}, {0, 0, 1}, {0, -1, 0}},
                                      {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}},  {{-1, 0, 0}, {0, 1, 0}, {0, 0, -1}}};

RenderCamera face_camera(int face, vec3 centre, int size, float znear, float zfar) {
  RenderCamera c = RenderCamera::from_fov(90.f, size, size, znear, zfar);
  for (int axis = 0; axis < 3; ++axis)
    for (int r = 0; r < 3; ++r) c.world_T_camera.R.m[r][axis] = kFaceAxes[face][axis][r];
  c.world_T_camera.t = centre;
  return c;
}

std::vector<uchar3> flip_rows(const std::vector<uchar3>& v, int w, int h) {
  std::vector<uchar3> out(v.size());
  for (int y = 0; y < h; ++y)
    std::copy_n(v.begin() + static_cast<std::ptrdiff_t>(y) * w, w,
                out.begin() + static_cast<std::ptrdiff_t>(h - 1 - y) * w);
  return out;
}

// Eye-space normals as colours (n * 0.5 + 0.5), black where there is no fluid.
Image<uchar3> normals_to_rgb(const std::vector<float>& v, int w, int h) {
  std::vector<uchar3> out(static_cast<std::size_t>(w) * h, uchar3{0, 0, 0});
  for (std::size_t i = 0; i < out.size(); ++i) {
    if (v[4 * i + 3] <= 0.f) continue;
    auto c = [&](int k) { return static_cast<std::uint8_t>(std::clamp(v[4 * i + k] * 127.5f + 127.5f, 0.f, 255.f)); };
    out[i] = {c(0), c(1), c(2)};
  }
  return Image<uchar3>::from_host(flip_rows(out, w, h), w, h, Device::CPU);
}

// The thickness stage image at the frame's size, so that all stage images line up.
Image<uchar3> upsample_nearest(Image<uchar3> im, int w, int h) {
  if (im.width() == w && im.height() == h) return im;
  const std::vector<uchar3> src = im.to_host();
  std::vector<uchar3> out(static_cast<std::size_t>(w) * h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      out[static_cast<std::size_t>(y) * w + x] =
          src[static_cast<std::size_t>(y * im.height() / h) * im.width() + x * im.width() / w];
  return Image<uchar3>::from_host(out, w, h, Device::CPU);
}

}  // namespace

Image<uchar3> float_to_grey(const std::vector<float>& v, int w, int h) {
  float lo = INFINITY, hi = -INFINITY;
  for (float x : v)
    if (x > 0.f) lo = std::min(lo, x), hi = std::max(hi, x);
  std::vector<uchar3> out(v.size(), uchar3{0, 0, 0});
  const float span = hi > lo ? hi - lo : 1.f;
  for (std::size_t i = 0; i < v.size(); ++i) {
    if (v[i] <= 0.f) continue;
    const auto g = static_cast<std::uint8_t>(40.f + 215.f * (v[i] - lo) / span);  // 40: visible above black
    out[i] = {g, g, g};
  }
  return Image<uchar3>::from_host(flip_rows(out, w, h), w, h, Device::CPU);
}

void Renderer::Impl::render_cube_map() {
  const int s = p.cube_size;
  cube = Texture(new_name(glGenTextures));
  glBindTexture(GL_TEXTURE_CUBE_MAP, cube);
  glTexStorage2D(GL_TEXTURE_CUBE_MAP, 1, GL_RGBA8, s, s);
  glTexParameteri(GL_TEXTURE_CUBE_MAP, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
  glTexParameteri(GL_TEXTURE_CUBE_MAP, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  glTexParameteri(GL_TEXTURE_CUBE_MAP, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
  glTexParameteri(GL_TEXTURE_CUBE_MAP, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
  glEnable(GL_TEXTURE_CUBE_MAP_SEAMLESS);
  Renderbuffer z(new_name(glGenRenderbuffers));
  glBindRenderbuffer(GL_RENDERBUFFER, z);
  glRenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH_COMPONENT24, s, s);
  Framebuffer fbo(new_name(glGenFramebuffers));
  glBindFramebuffer(GL_FRAMEBUFFER, fbo);
  glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, z);
  glViewport(0, 0, s, s);
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_LESS);
  glDisable(GL_CULL_FACE);
  const vec3 centre = (scene_lo + scene_hi) * 0.5f;
  shadow_live = false;  // the cube map holds the scan alone, lit as recorded
  for (int f = 0; f < 6; ++f) {
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_CUBE_MAP_POSITIVE_X + f, cube, 0);
    glClearColor(p.background.x, p.background.y, p.background.z, 1.f);
    glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
    draw_mesh(scene, face_camera(f, centre, s, p.znear, p.zfar), model_matrix(SE3::identity()), true,
              {0.7f, 0.7f, 0.7f}, p.light_scene);
  }
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  has_cube = true;
}

namespace {
void bind_tex(int unit, GLenum target, GLuint tex) {
  glActiveTexture(GL_TEXTURE0 + static_cast<GLenum>(unit));
  glBindTexture(target, tex);
}
}  // namespace

// Copies the scene's depth into the depth buffer of `dst` (w x h, scaled with nearest samples), so
// that the hardware depth test rejects sprites behind the scene before their fragment shader.
void Renderer::Impl::copy_scene_depth(GLuint dst, int dw, int dh) {
  glBindFramebuffer(GL_READ_FRAMEBUFFER, scene_fbo);
  glBindFramebuffer(GL_DRAW_FRAMEBUFFER, dst);
  glBlitFramebuffer(0, 0, w, h, 0, 0, dw, dh, GL_DEPTH_BUFFER_BIT, GL_NEAREST);
  glBindFramebuffer(GL_FRAMEBUFFER, dst);
}

// SSFR 1: nearest sphere depth per pixel, in front of the scene.
void Renderer::Impl::fluid_depth_pass(std::int64_t n, float sphere_r, const RenderCamera& cam) {
  if (use_compute_splat()) return fluid_depth_splat(n, sphere_r, cam);
  glBindFramebuffer(GL_FRAMEBUFFER, fluid_depth_fbo);
  glClearColor(0.f, 0.f, 0.f, 0.f);
  if (p.depth_prepass) {
    glClear(GL_COLOR_BUFFER_BIT);
    copy_scene_depth(fluid_depth_fbo, w, h);
  } else {
    glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
  }
  glEnable(GL_DEPTH_TEST);
  glDepthMask(GL_TRUE);
  bind_tex(0, GL_TEXTURE_2D, scene_depth);
  fluid_depth_prog.use();
  glUniform1i(fluid_depth_prog.loc("u_scene_depth"), 0);
  glUniform1i(fluid_depth_prog.loc("u_test_scene"), !p.depth_prepass);
  draw_spheres(fluid_depth_prog, n, phase::kFluid, sphere_r, cam);
}

// SSFR 2: every sphere's chord, added up, at 1 / thickness_downsample resolution; sprites wholly
// behind the scene fail the depth test (no depth writes), the rest are cut at the scene.
void Renderer::Impl::fluid_thickness_pass(std::int64_t n, float sphere_r, float radius, const RenderCamera& cam) {
  RenderCamera low = cam;
  low.K = scale_intrinsics(cam.K, tw, th);
  glViewport(0, 0, tw, th);
  if (use_compute_splat()) {
    fluid_thickness_splat(n, sphere_r, low);
    return thickness_blur(low, radius);
  }
  glBindFramebuffer(GL_FRAMEBUFFER, thick_fbo[0]);
  glClear(GL_COLOR_BUFFER_BIT);
  if (p.depth_prepass) {
    copy_scene_depth(thick_fbo[0], tw, th);
    glEnable(GL_DEPTH_TEST);
    glDepthMask(GL_FALSE);
  } else {
    glDisable(GL_DEPTH_TEST);
  }
  glEnable(GL_BLEND);
  glBlendFunc(GL_ONE, GL_ONE);
  bind_tex(0, GL_TEXTURE_2D, scene_depth);
  fluid_thick_prog.use();
  glUniform1i(fluid_thick_prog.loc("u_scene_depth"), 0);
  const float s = p.fluid_radius_scale;
  glUniform1f(fluid_thick_prog.loc("u_thickness_scale"), 6.f / (std::numbers::pi_v<float> * s * s * s));
  draw_spheres(fluid_thick_prog, n, phase::kFluid, sphere_r, low);
  glDisable(GL_BLEND);
  glDisable(GL_DEPTH_TEST);
  glDepthMask(GL_TRUE);
  thickness_blur(low, radius);
}

// Smoothing of the thickness over the particle spacing, at its resolution (the viewport is tw x
// th on entry): the depth filter's half-width (filter_size radii), projected at the filtered
// depth, no range weight.
void Renderer::Impl::thickness_blur(const RenderCamera& low, float radius) {
  glDisable(GL_DEPTH_TEST);  // thick_fbo[0] has the raster path's depth buffer attached
  const Program& fp = filter_program();
  set_camera_uniforms(fp, low);
  glBindVertexArray(empty_vao);
  const int down = std::max(1, p.thickness_downsample);
  glUniform1f(fp.loc("u_world_radius"), p.filter_size * radius);
  glUniform1i(fp.loc("u_max_px"), std::max(1, p.filter_max_px / down));
  glUniform1i(fp.loc("u_max_taps"), std::max(1, p.filter_max_taps / down));
  glUniform1f(fp.loc("u_range_sigma"), 0.f);
  glUniform1i(fp.loc("u_skip_empty"), 0);
  glUniform1f(fp.loc("u_fill_world"), 0.f);
  bind_tex(1, GL_TEXTURE_2D, fluid_depth[0]);
  glUniform1i(fp.loc("u_width_depth"), 1);
  filter_pass(thick[0], thick[1], thick_fbo[1], 1, 0, tw, th);
  filter_pass(thick[1], thick[0], thick_fbo[0], 0, 1, tw, th);
  glViewport(0, 0, w, h);
}

// The bound filter program (filter_program()) over one axis; compute writes `dst` as an image,
// the fragment version renders into dst_fbo.
void Renderer::Impl::filter_pass(GLuint src, GLuint dst, GLuint dst_fbo, int dx, int dy, int iw, int ih) {
  const Program& fp = filter_program();
  bind_tex(0, GL_TEXTURE_2D, src);
  glUniform1i(fp.loc("u_src"), 0);
  glUniform2i(fp.loc("u_dir"), dx, dy);
  if (use_compute_splat()) {
    glBindImageTexture(0, dst, 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_R32F);
    return dispatch_screen(iw, ih);
  }
  glBindFramebuffer(GL_FRAMEBUFFER, dst_fbo);
  glDrawArrays(GL_TRIANGLES, 0, 3);
}

// SSFR 3: the separable edge-preserving filter of the depth, world-sized.
void Renderer::Impl::fluid_filter_passes(float radius, const RenderCamera& cam) {
  glDisable(GL_DEPTH_TEST);
  const Program& fp = filter_program();
  set_camera_uniforms(fp, cam);
  glBindVertexArray(empty_vao);
  glUniform1f(fp.loc("u_world_radius"), p.filter_size * radius);
  glUniform1i(fp.loc("u_max_px"), p.filter_max_px);
  glUniform1i(fp.loc("u_max_taps"), p.filter_max_taps);
  glUniform1f(fp.loc("u_range_sigma"), p.filter_depth_sigma * radius);
  glUniform1i(fp.loc("u_skip_empty"), 1);
  glUniform1i(fp.loc("u_narrow_range"), p.fluid_filter == FluidFilter::narrow_range);
  bind_tex(1, GL_TEXTURE_2D, scene_depth);
  glUniform1i(fp.loc("u_scene_depth_w"), 1);
  for (int it = 0; it < p.filter_iterations; ++it) {
    // The gap fill closes the holes between spheres once; later iterations only smooth. The
    // anisotropic kernels close a spread layer themselves, so what is left between their
    // ellipsoids is a real gap (a drop beside the puddle), which a fill would bridge with a
    // rectangle of water along the rows and columns (docs/RENDERING.md, Water: gap fill).
    const bool fill = it == 0 && !aniso_live;
    glUniform1f(fp.loc("u_fill_world"), fill ? p.fluid_gap_fill * radius : 0.f);
    // Every other iteration runs the columns first, so that the filter ends along the rows. At a
    // rim the window of the pass across it is one-sided and its result differs from line to line
    // (each holds other splats' edges); the pass after smooths that along its own direction.
    // Always ending with the columns left those differences along the rows: a puddle seen at a
    // grazing angle, whose front rim runs along the rows, showed vertical streaks in its normals.
    const int first = it % 2;
    filter_pass(fluid_depth[0], fluid_depth[1], fluid_filter_fbo[1], 1 - first, first, w, h);
    filter_pass(fluid_depth[1], fluid_depth[0], fluid_filter_fbo[0], first, 1 - first, w, h);
  }
}

// SSFR 4: normals from the filtered depth.
void Renderer::Impl::normals_pass(const RenderCamera& cam) {
  const bool compute = use_compute_splat();
  const Program& np = compute ? normal_cprog : normal_prog;
  set_camera_uniforms(np, cam);
  bind_tex(0, GL_TEXTURE_2D, fluid_depth[0]);
  glUniform1i(np.loc("u_depth"), 0);
  if (compute) {
    glBindImageTexture(0, normals, 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_RGBA16F);
    return dispatch_screen(w, h);
  }
  glBindFramebuffer(GL_FRAMEBUFFER, normal_fbo);
  glDrawArrays(GL_TRIANGLES, 0, 3);
}

// SSFR 5: shading over the scene, into final_fbo's colour, reflection and refraction targets.
// `contact`: metres between the water's back and the scene within which the water wets it.
void Renderer::Impl::composite_pass(const RenderCamera& cam, float contact) {
  const bool compute = use_compute_splat();
  const Program& cp = compute ? composite_cprog : composite_prog;
  set_camera_uniforms(cp, cam);
  bind_tex(0, GL_TEXTURE_2D, scene_color);
  bind_tex(1, GL_TEXTURE_2D, fluid_depth[0]);
  bind_tex(2, GL_TEXTURE_2D, normals);
  bind_tex(3, GL_TEXTURE_2D, thick[0]);
  bind_tex(4, GL_TEXTURE_CUBE_MAP, cube);
  bind_tex(5, GL_TEXTURE_2D, scene_depth);
  const char* samplers[] = {"u_scene_color", "u_fluid_depth", "u_normal", "u_thickness", "u_cube", "u_scene_depth"};
  for (int i = 0; i < 6; ++i) glUniform1i(cp.loc(samplers[i]), i);
  const bool use_cube = has_cube && p.view == RenderView::mesh;
  glUniform1i(cp.loc("u_use_cube"), use_cube);
  // Without a cube map, the Kinect image's mean colour (or the mesh view's background) is what
  // the surface reflects.
  const vec3 env = p.view == RenderView::kinect && has_kinect ? kin_mean : srgb_to_linear(p.background);
  glUniform3f(cp.loc("u_env"), env.x, env.y, env.z);
  glUniform1i(cp.loc("u_image_env"), p.view == RenderView::kinect && has_kinect && p.ssr_steps > 0);
  const std::vector<float> R = {
      cam.world_T_camera.R.m[0][0], cam.world_T_camera.R.m[1][0], cam.world_T_camera.R.m[2][0],
      cam.world_T_camera.R.m[0][1], cam.world_T_camera.R.m[1][1], cam.world_T_camera.R.m[2][1],
      cam.world_T_camera.R.m[0][2], cam.world_T_camera.R.m[1][2], cam.world_T_camera.R.m[2][2]};
  glUniformMatrix3fv(cp.loc("u_world_R_eye"), 1, GL_FALSE, R.data());
  glUniform3f(cp.loc("u_absorption"), p.absorption.x, p.absorption.y, p.absorption.z);
  glUniform1f(cp.loc("u_ior"), p.ior);
  glUniform1f(cp.loc("u_f0"), p.fresnel_f0);
  glUniform1f(cp.loc("u_roughness"), p.fluid_roughness);
  glUniform1f(cp.loc("u_light_intensity"), p.light_intensity);
  glUniform1i(cp.loc("u_ssr_steps"), p.ssr_steps);
  glUniform1f(cp.loc("u_ssr_distance"), p.ssr_distance);
  glUniform1f(cp.loc("u_contact"), contact);
  glUniform1i(cp.loc("u_wet"), p.fluid_wet);
  // A real surface under the water: the light's share of its light (shadow_strength) has crossed
  // the water already where the fluid is in the shadow map; the composite attenuates the rest.
  // In the Kinect view the scene's depth is the recorded one, and window depth 1 a pixel without a
  // reading (kinect_bg.frag); in the mesh view it is the background, where nothing was scanned.
  glUniform1i(cp.loc("u_depth_holes"), p.view == RenderView::kinect && has_kinect);
  glUniform1f(cp.loc("u_diffuse_share"), shadow_live && fluid_shadow_live ? 1.f - p.shadow_strength : 1.f);
  glUniform1f(cp.loc("u_drop_radius"), contact / p.fluid_radius_scale);  // the particle's own radius
  if (compute) {
    const GLuint out[] = {final_color, reflect_color, refract_color};
    for (GLuint i = 0; i < 3; ++i) glBindImageTexture(i, out[i], 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_RGBA8);
    return dispatch_screen(w, h);
  }
  glBindFramebuffer(GL_FRAMEBUFFER, final_fbo);
  glDrawArrays(GL_TRIANGLES, 0, 3);
}

// Returns false when no fluid particle is drawn.
bool Renderer::Impl::draw_fluid(std::int64_t n, float radius, const RenderCamera& cam) {
  if (fluid_count == 0) return false;
  const float sphere_r = radius * p.fluid_radius_scale;
  fluid_depth_pass(n, sphere_r, cam);
  timer.mark("fluid_depth");
  if (p.stage_images)
    stages.push_back({"1_depth", float_to_grey(read_float(fluid_depth_fbo, 0, GL_RED, 1, w, h), w, h)});
  // The filter before the thickness: the thickness is smoothed over widths projected at the
  // filtered depth (which the gap fill has closed).
  fluid_filter_passes(radius, cam);
  timer.mark("fluid_filter");
  fluid_thickness_pass(n, sphere_r, radius, cam);
  timer.mark("fluid_thickness");
  normals_pass(cam);
  timer.mark("fluid_normals");
  composite_pass(cam, sphere_r);
  glBindVertexArray(0);
  glEnable(GL_DEPTH_TEST);
  timer.mark("fluid_composite");
  return true;
}

void Renderer::Impl::capture_stages() {
  stages.push_back({"2_depth_filtered", float_to_grey(read_float(fluid_filter_fbo[0], 0, GL_RED, 1, w, h), w, h)});
  stages.push_back({"3_normals", normals_to_rgb(read_float(normal_fbo, 0, GL_RGBA, 4, w, h), w, h)});
  stages.push_back(
      {"4_thickness", upsample_nearest(float_to_grey(read_float(thick_fbo[0], 0, GL_RED, 1, tw, th), tw, th), w, h)});
  stages.push_back({"5_reflection", read_rgb8(final_fbo, 1, w, h)});
  stages.push_back({"6_refraction", read_rgb8(final_fbo, 2, w, h)});
  stages.push_back({"7_composite", read_rgb8(final_fbo, 0, w, h)});
}

}  // namespace seamless
