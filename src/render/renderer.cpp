// Renderer: programs, targets, the scene (mesh or Kinect view), rigid boxes, cloth, particles.
// The fluid passes are in renderer_fluid.cpp.
#include <algorithm>
#include <cmath>

#include "core/error.hpp"
#include "core/log.hpp"
#include "core/mesh.hpp"
#include "core/phase.hpp"
#include "render/renderer_impl.hpp"

namespace seamless {

vec3 srgb_to_linear(vec3 c) {  // IEC 61966-2-1, as color.glsl
  auto f = [](float x) { return x <= 0.04045f ? x / 12.92f : std::pow((x + 0.055f) / 1.055f, 2.4f); };
  return {f(c.x), f(c.y), f(c.z)};
}

namespace {

// The mean of an sRGB image (width w) over the rectangle a, in linear radiance (what the fluid
// reflects in the Kinect view), from every 4th pixel of every 4th row: a tint, for which 19,200
// samples of a 640 x 480 frame are plenty, where every pixel cost a share of each live frame.
vec3 mean_linear_color(const uchar3* c, int w, const PixelRect& a) {
  constexpr int kStride = 4;
  float lut[256];
  for (int i = 0; i < 256; ++i) lut[i] = srgb_to_linear(vec3{i / 255.f, 0.f, 0.f}).x;
  double r = 0, g = 0, b = 0, n = 0;
  for (int y = a.y; y < a.y + a.height; y += kStride)
    for (int x = a.x; x < a.x + a.width; x += kStride) {
      const uchar3& q = c[static_cast<std::size_t>(y) * w + x];
      r += lut[q.x], g += lut[q.y], b += lut[q.z], n += 1;
    }
  n = std::max(n, 1.0);
  return {static_cast<float>(r / n), static_cast<float>(g / n), static_cast<float>(b / n)};
}

// Texture tex (w x h) from host pixels through the pixel buffer pbo: the host's part is one copy
// into a fresh buffer (the last frame's may still be in transfer: orphaned, not waited for), the
// transfer and any conversion (3-byte RGB texels) run on the GPU. Straight from host memory the
// driver converted and copied each frame's colour image before returning (docs/PERFORMANCE.md,
// "The live loop's host side").
void upload_texture(GLuint pbo, GLuint tex, int w, int h, GLenum format, GLenum type, const void* data,
                    std::size_t texel_bytes) {
  const auto bytes = static_cast<GLsizeiptr>(static_cast<std::size_t>(w) * h * texel_bytes);
  glBindBuffer(GL_PIXEL_UNPACK_BUFFER, pbo);
  glBufferData(GL_PIXEL_UNPACK_BUFFER, bytes, nullptr, GL_STREAM_DRAW);
  glBufferSubData(GL_PIXEL_UNPACK_BUFFER, 0, bytes, data);
  glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
  glBindTexture(GL_TEXTURE_2D, tex);
  glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, w, h, format, type, nullptr);
  glBindBuffer(GL_PIXEL_UNPACK_BUFFER, 0);
}

}  // namespace

void Renderer::Impl::build_programs() {
  auto vs = [](std::vector<std::string> f) { return ShaderStage{GL_VERTEX_SHADER, std::move(f)}; };
  auto fs = [](std::vector<std::string> f) { return ShaderStage{GL_FRAGMENT_SHADER, std::move(f)}; };
  const std::vector<std::string> sphere_fs = {"camera.glsl", "sphere_hit.glsl"};
  auto with = [](std::vector<std::string> a, const char* f) {
    a.push_back(f);
    return a;
  };
  // Surfaces that receive the virtual objects' shadows (shadow.glsl).
  const std::vector<std::string> receiver = {"color.glsl", "shadow.glsl", "mesh.frag"};
  mesh_prog = Program("mesh", {vs({"mesh.vert"}), fs(receiver)});
  cloth_prog = Program("cloth", {vs({"cloth.vert"}), fs({"color.glsl", "shadow.glsl", "cloth.frag"})});
  particle_prog = Program("particles", {vs({"sphere.vert"}), fs(with(sphere_fs, "particle.frag"))});
  fluid_depth_prog = Program("fluid depth", {vs({"sphere.vert"}), fs(with(sphere_fs, "ssfr_depth.frag"))});
  fluid_thick_prog = Program("fluid thickness", {vs({"sphere.vert"}), fs(with(sphere_fs, "ssfr_thickness.frag"))});
  kinect_prog = Program(
      "kinect view",
      {vs({"fullscreen.vert"}), fs({"camera.glsl", "color.glsl", "shadow.glsl", "occlusion.glsl", "kinect_bg.frag"})});
  auto screen = [&](const char* name, const char* body, const char* main) {
    return Program(name, {vs({"fullscreen.vert"}), fs({"camera.glsl", "color.glsl", body, main})});
  };
  filter_prog = screen("fluid filter", "ssfr_filter.glsl", "ssfr_filter.frag");
  normal_prog = screen("fluid normals", "ssfr_normal.glsl", "ssfr_normal.frag");
  composite_prog = screen("fluid composite", "ssfr_composite.glsl", "ssfr_composite.frag");
}

void Renderer::Impl::make_targets() {
  scene_color = make_texture_2d(GL_RGBA8, w, h, GL_LINEAR);
  scene_depth = make_texture_2d(GL_DEPTH_COMPONENT32F, w, h);
  scene_fbo = make_framebuffer({scene_color}, scene_depth, "scene");
  final_color = make_texture_2d(GL_RGBA8, w, h);
  reflect_color = make_texture_2d(GL_RGBA8, w, h);
  refract_color = make_texture_2d(GL_RGBA8, w, h);
  final_fbo = make_framebuffer({final_color, reflect_color, refract_color}, 0, "fluid composite");
  const int ds = std::max(1, p.thickness_downsample);
  tw = std::max(1, w / ds), th = std::max(1, h / ds);
  for (int i = 0; i < 2; ++i) {
    fluid_depth[i] = make_texture_2d(GL_R32F, w, h);
    thick[i] = make_texture_2d(GL_R32F, tw, th, GL_LINEAR);  // upsampled bilinearly by the composite
    fluid_filter_fbo[i] = make_framebuffer({fluid_depth[i]}, 0, "fluid filter");
    thick_fbo[i] = make_framebuffer({thick[i]}, 0, "fluid thickness");
  }
  // The thickness pass tests its sprites against the scene depth, scaled down into this.
  thick_zbuf = Renderbuffer(new_name(glGenRenderbuffers));
  glBindRenderbuffer(GL_RENDERBUFFER, thick_zbuf);
  glRenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH_COMPONENT32F, tw, th);
  glBindFramebuffer(GL_FRAMEBUFFER, thick_fbo[0]);
  glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, thick_zbuf);
  normals = make_texture_2d(GL_RGBA16F, w, h);
  normal_fbo = make_framebuffer({normals}, 0, "fluid normals");
  fluid_zbuf = Renderbuffer(new_name(glGenRenderbuffers));
  glBindRenderbuffer(GL_RENDERBUFFER, fluid_zbuf);
  glRenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH_COMPONENT32F, w, h);
  fluid_depth_fbo = make_framebuffer({fluid_depth[0]}, 0, "fluid depth");
  glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, fluid_zbuf);
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  make_splat_targets();
}

// Unit box [-1, 1]^3 with a normal per face (24 vertices), scaled to the body's half extents.
void Renderer::Impl::make_box() {
  std::vector<vec3> p, n;
  std::vector<int3> t;
  for (int axis = 0; axis < 3; ++axis)
    for (float s : {-1.f, 1.f}) {
      vec3 nn{0, 0, 0};
      (&nn.x)[axis] = s;
      const int u = (axis + 1) % 3, v = (axis + 2) % 3;
      const int base = static_cast<int>(p.size());
      // Corners run counter-clockwise about e_u x e_v = e_axis; reversed on the negative face, so
      // that every face winds counter-clockwise seen from outside (its normal's side).
      for (auto [a, b] : {std::pair{-1.f, -1.f}, {1.f, -1.f}, {1.f, 1.f}, {-1.f, 1.f}}) {
        vec3 q = nn;
        (&q.x)[u] = a, (&q.x)[v] = b;
        p.push_back(q), n.push_back(nn);
      }
      if (s > 0) t.push_back({base, base + 1, base + 2}), t.push_back({base, base + 2, base + 3});
      else t.push_back({base, base + 2, base + 1}), t.push_back({base, base + 3, base + 2});
    }
  box.upload(p, n, {}, t, GL_STATIC_DRAW);
}

vec3 Renderer::Impl::light_eye(const RenderCamera& cam) const {
  const vec3 to_light = -normalize(p.light_dir);
  return transpose(cam.world_T_camera.R) * to_light;
}

void Renderer::Impl::set_camera_uniforms(const Program& prog, const RenderCamera& cam) const {
  prog.use();
  glUniform4f(prog.loc("u_K"), cam.K.fx, cam.K.fy, cam.K.cx, cam.K.cy);
  glUniform2f(prog.loc("u_size"), static_cast<float>(cam.K.width), static_cast<float>(cam.K.height));
  glUniform2f(prog.loc("u_near_far"), cam.znear, cam.zfar);
  const Mat4 V = view_matrix(cam.world_T_camera), P = projection_matrix(cam.K, cam.znear, cam.zfar);
  glUniformMatrix4fv(prog.loc("u_view"), 1, GL_FALSE, V.data());
  glUniformMatrix4fv(prog.loc("u_proj"), 1, GL_FALSE, P.data());
  glUniformMatrix4fv(prog.loc("u_world_T_camera"), 1, GL_FALSE, model_matrix(cam.world_T_camera).data());
  const vec3 l = light_eye(cam);
  glUniform3f(prog.loc("u_light"), l.x, l.y, l.z);
  glUniform1f(prog.loc("u_ambient"), p.ambient);
  shadow_uniforms(prog);
}

void Renderer::Impl::draw_mesh(const GlMesh& m, const RenderCamera& cam, const Mat4& model, bool vertex_color,
                               vec3 tint, bool lit, bool two_sided) {
  set_camera_uniforms(mesh_prog, cam);
  glUniformMatrix4fv(mesh_prog.loc("u_model"), 1, GL_FALSE, model.data());
  glUniform1i(mesh_prog.loc("u_vertex_color"), vertex_color);
  glUniform3f(mesh_prog.loc("u_tint"), tint.x, tint.y, tint.z);
  glUniform1i(mesh_prog.loc("u_lit"), lit);
  glUniform1i(mesh_prog.loc("u_two_sided"), two_sided);
  m.draw();
}

void Renderer::Impl::draw_scene(const RenderCamera& cam) {
  if (!p.show_scene) return;
  if (p.view == RenderView::kinect && has_kinect) {
    // Depth test always passes: the image is the background and sets every pixel's depth.
    glDepthFunc(GL_ALWAYS);
    set_camera_uniforms(kinect_prog, cam);
    glActiveTexture(GL_TEXTURE0), glBindTexture(GL_TEXTURE_2D, kin_rgb);
    glActiveTexture(GL_TEXTURE1), glBindTexture(GL_TEXTURE_2D, kin_depth);
    glUniform1i(kinect_prog.loc("u_rgb"), 0);
    glUniform1i(kinect_prog.loc("u_depth"), 1);
    const PixelRect v = fit_aspect(kin_region, w, h);
    glUniform4f(kinect_prog.loc("u_crop"), static_cast<float>(v.x), static_cast<float>(v.y),
                static_cast<float>(v.width), static_cast<float>(v.height));
    glUniform2f(kinect_prog.loc("u_image_size"), static_cast<float>(kin_K.width), static_cast<float>(kin_K.height));
    glUniform1i(kinect_prog.loc("u_plane_count"), static_cast<GLint>(kin_planes.size()));
    if (!kin_planes.empty())
      glUniform4fv(kinect_prog.loc("u_planes"), static_cast<GLsizei>(kin_planes.size()), &kin_planes[0].x);
    glBindVertexArray(empty_vao);
    glDrawArrays(GL_TRIANGLES, 0, 3);
    glDepthFunc(GL_LESS);
  } else if (p.view == RenderView::mesh && has_scene) {
    draw_mesh(scene, cam, model_matrix(SE3::identity()), true, {0.7f, 0.7f, 0.7f}, p.light_scene);
  }
}

void Renderer::Impl::upload_particles(const DrawList& list) {
  const auto n = static_cast<std::int64_t>(list.positions.size());
  if (!list.phases.empty() && static_cast<std::int64_t>(list.phases.size()) != n)
    throw Error("render: DrawList has " + std::to_string(n) + " positions but " + std::to_string(list.phases.size()) +
                " phases; give one phase per particle (or none: all fluid)");
  if (n > part_capacity) {
    part_capacity = std::max<std::int64_t>(n, 2 * part_capacity);
    glBindBuffer(GL_ARRAY_BUFFER, part_pos);
    glBufferData(GL_ARRAY_BUFFER, part_capacity * static_cast<GLsizeiptr>(sizeof(vec3)), nullptr, GL_STREAM_DRAW);
    glBindBuffer(GL_ARRAY_BUFFER, part_phase);
    glBufferData(GL_ARRAY_BUFFER, part_capacity * static_cast<GLsizeiptr>(sizeof(std::uint32_t)), nullptr,
                 GL_STREAM_DRAW);
    glBindBuffer(GL_ARRAY_BUFFER, part_ell);
    glBufferData(GL_ARRAY_BUFFER, part_capacity * FluidEllipsoids::kVec4s * static_cast<GLsizeiptr>(sizeof(vec4)),
                 nullptr, GL_STREAM_DRAW);
  }
  fluid_count = list.phases.empty() ? n : 0;
  for (std::uint32_t ph : list.phases) fluid_count += phase::is(ph, phase::kFluid) ? 1 : 0;
  aniso_live = ellipsoids_in_buffer = false;
  if (n == 0) return;
  glBindBuffer(GL_ARRAY_BUFFER, part_pos);
  glBufferSubData(GL_ARRAY_BUFFER, 0, n * static_cast<GLsizeiptr>(sizeof(vec3)), list.positions.data());
  glBindBuffer(GL_ARRAY_BUFFER, part_phase);
  if (list.phases.empty()) {
    std::vector<std::uint32_t> fluid(static_cast<std::size_t>(n), phase::kFluid);
    glBufferSubData(GL_ARRAY_BUFFER, 0, n * static_cast<GLsizeiptr>(sizeof(std::uint32_t)), fluid.data());
  } else {
    glBufferSubData(GL_ARRAY_BUFFER, 0, n * static_cast<GLsizeiptr>(sizeof(std::uint32_t)), list.phases.data());
  }
  upload_ellipsoids(list, n);
}

std::optional<Renderer::EllipsoidSizes> Renderer::Impl::ellipsoid_sizes(float radius) const {
  if (!p.fluid_anisotropy || !use_compute_splat() || !(radius > 0.f)) return std::nullopt;
  return Renderer::EllipsoidSizes{radius * p.fluid_radius_scale, FluidEllipsoids::kNeighbourhoodRadii * radius};
}

// This frame's fluid ellipsoids for the splats: the list's own, or computed here on the CPU when
// the anisotropic kernels are on and the list brings none (a host run, a test, `seamless render`).
void Renderer::Impl::upload_ellipsoids(const DrawList& list, std::int64_t n) {
  aniso_live = false;
  const std::optional<Renderer::EllipsoidSizes> sizes = ellipsoid_sizes(list.particle_radius);
  if (!sizes || fluid_count == 0 || n == 0) return;
  const std::int64_t count = n * FluidEllipsoids::kVec4s;
  const vec4* e = list.ellipsoids.data();
  if (list.ellipsoids.empty()) {
    std::vector<std::uint32_t> all_fluid;
    if (list.phases.empty()) all_fluid.assign(static_cast<std::size_t>(n), phase::kFluid);
    e = cpu_shapes.compute(list.positions.data(), list.phases.empty() ? all_fluid.data() : list.phases.data(), n,
                           sizes->radius, sizes->h);
  } else if (static_cast<std::int64_t>(list.ellipsoids.size()) != count) {
    throw Error("render: DrawList has " + std::to_string(list.ellipsoids.size()) + " ellipsoid vec4s for " +
                std::to_string(n) + " particles; give " + std::to_string(FluidEllipsoids::kVec4s) +
                " per particle (FluidEllipsoids) or none");
  }
  glBindBuffer(GL_ARRAY_BUFFER, part_ell);
  glBufferSubData(GL_ARRAY_BUFFER, 0, count * static_cast<GLsizeiptr>(sizeof(vec4)), e);
  aniso_live = ellipsoids_in_buffer = true;
}

void Renderer::Impl::draw_spheres(const Program& prog, std::int64_t n, std::uint32_t mask, float radius,
                                  const RenderCamera& cam) {
  set_camera_uniforms(prog, cam);
  glUniform1f(prog.loc("u_radius"), radius);
  glUniform1f(prog.loc("u_fmax"), std::max(cam.K.fx, cam.K.fy));
  glUniform1ui(prog.loc("u_phase_mask"), mask);
  glUniform1f(prog.loc("u_max_point_size"), p.max_point_size);
  glBindVertexArray(part_vao);
  glDrawArrays(GL_POINTS, 0, static_cast<GLsizei>(n));
  glBindVertexArray(0);
}

const GlMesh& Renderer::Impl::body_mesh(const std::shared_ptr<const BodyMesh>& m) {
  for (auto it = body_meshes.begin(); it != body_meshes.end();)
    it = it->second.first.expired() ? body_meshes.erase(it) : std::next(it);
  auto it = body_meshes.find(m.get());
  if (it != body_meshes.end()) return it->second.second;
  if (m->normals.size() != m->positions.size())
    throw Error("render: rigid body mesh has " + std::to_string(m->positions.size()) + " positions but " +
                std::to_string(m->normals.size()) + " normals");
  auto& e = body_meshes[m.get()];
  e.first = m;
  e.second.upload(m->positions, m->normals, {}, m->triangles, GL_STATIC_DRAW);
  return e.second;
}

namespace {

// Where each cloth vertex sits in its sheet's grid (cells), for the dye pattern: sheets are grids
// (physics make_cloth: particle first + j nx + i, triangles (a, a + 1, a + nx + 1) and
// (a, a + nx + 1, a + nx)), so each connected sheet's first id is its smallest and its row length
// nx comes from a triangle whose second vertex follows its first. A sheet of another topology
// gets (0, 0) everywhere: plain dye. Vertices lo .. hi.
std::vector<vec2> cloth_grid_uv(const std::vector<int3>& tris, int lo, int hi) {
  std::vector<int> root(static_cast<std::size_t>(hi - lo + 1));
  for (std::size_t i = 0; i < root.size(); ++i) root[i] = static_cast<int>(i);
  auto find = [&](int i) {
    while (root[i] != i) i = root[i] = root[root[i]];
    return i;
  };
  for (const int3& t : tris) {
    const int a = find(t.x - lo);
    root[find(t.y - lo)] = a, root[find(t.z - lo)] = a;
  }
  const int m = static_cast<int>(root.size());
  std::vector<int> first(m, -1), nx(m, 0);  // per root
  for (int i = 0; i < m; ++i)
    if (first[find(i)] < 0) first[find(i)] = i;  // ascending: the smallest id of the sheet
  for (const int3& t : tris) {
    const int r = find(t.x - lo), k = t.z - t.x - 1;
    if (t.y != t.x + 1 || k < 1) continue;
    nx[r] = nx[r] == 0 || nx[r] == k ? k : -1;  // -1: inconsistent, not a grid
  }
  std::vector<vec2> uv(root.size(), vec2{0.f, 0.f});
  for (int i = 0; i < m; ++i) {
    const int r = find(i), k = nx[r];
    if (k > 0) uv[i] = {static_cast<float>((i - first[r]) % k), static_cast<float>((i - first[r]) / k)};
  }
  return uv;
}

void buffer_texture(Texture& tex, GLuint buf, GLenum format) {
  if (!tex) tex = Texture(new_name(glGenTextures));
  glBindTexture(GL_TEXTURE_BUFFER, tex);
  glTexBuffer(GL_TEXTURE_BUFFER, format, buf);
}
}  // namespace

// Indices and per-vertex triangle rings of the sheets, re-made only when the topology changes
// (a sheet is spawned); positions stay in the particle buffer.
void Renderer::Impl::upload_cloth(const std::vector<int3>& tris, std::int64_t n) {
  const bool same = tris.size() == cloth_tris.size() &&
                    std::equal(tris.begin(), tris.end(), cloth_tris.begin(),
                               [](int3 a, int3 b) { return a.x == b.x && a.y == b.y && a.z == b.z; });
  if (same) return;
  int lo = tris[0].x, hi = lo;
  for (const int3& t : tris) lo = std::min({lo, t.x, t.y, t.z}), hi = std::max({hi, t.x, t.y, t.z});
  if (lo < 0 || hi >= n)
    throw Error("render: cloth triangle index " + std::to_string(lo < 0 ? lo : hi) + " is outside the " +
                std::to_string(n) + " particles drawn");
  std::vector<int> off(static_cast<std::size_t>(hi - lo + 2), 0), ring;
  for (const int3& t : tris) ++off[t.x - lo + 1], ++off[t.y - lo + 1], ++off[t.z - lo + 1];
  for (std::size_t i = 1; i < off.size(); ++i) off[i] += off[i - 1];
  ring.resize(2 * static_cast<std::size_t>(off.back()));
  std::vector<int> fill(off.begin(), off.end() - 1);
  auto put = [&](int i, int j, int k) {
    const int at = fill[i - lo]++;
    ring[2 * at] = j, ring[2 * at + 1] = k;
  };
  for (const int3& t : tris) put(t.x, t.y, t.z), put(t.y, t.z, t.x), put(t.z, t.x, t.y);  // winding kept
  if (!cloth_vao) {
    cloth_vao = VertexArray(new_name(glGenVertexArrays));
    cloth_idx = GlBuffer(new_name(glGenBuffers)), cloth_ring_off = GlBuffer(new_name(glGenBuffers));
    cloth_ring = GlBuffer(new_name(glGenBuffers)), cloth_uv = GlBuffer(new_name(glGenBuffers));
  }
  glBindVertexArray(cloth_vao);
  glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, cloth_idx);
  glBufferData(GL_ELEMENT_ARRAY_BUFFER, static_cast<GLsizeiptr>(tris.size() * sizeof(int3)), tris.data(),
               GL_STATIC_DRAW);
  glBindVertexArray(0);
  glBindBuffer(GL_TEXTURE_BUFFER, cloth_ring_off);
  glBufferData(GL_TEXTURE_BUFFER, static_cast<GLsizeiptr>(off.size() * sizeof(int)), off.data(), GL_STATIC_DRAW);
  glBindBuffer(GL_TEXTURE_BUFFER, cloth_ring);
  glBufferData(GL_TEXTURE_BUFFER, static_cast<GLsizeiptr>(ring.size() * sizeof(int)), ring.data(), GL_STATIC_DRAW);
  const std::vector<vec2> uv = cloth_grid_uv(tris, lo, hi);
  glBindBuffer(GL_TEXTURE_BUFFER, cloth_uv);
  glBufferData(GL_TEXTURE_BUFFER, static_cast<GLsizeiptr>(uv.size() * sizeof(vec2)), uv.data(), GL_STATIC_DRAW);
  glBindBuffer(GL_TEXTURE_BUFFER, 0);
  buffer_texture(ring_off_tbo, cloth_ring_off, GL_R32I);
  buffer_texture(ring_tbo, cloth_ring, GL_RG32I);
  buffer_texture(uv_tbo, cloth_uv, GL_RG32F);
  cloth_tris = tris;
  cloth_first = lo;
}

// The particle positions and the sheets' rings for cloth.vert (camera or shadow map).
void Renderer::Impl::bind_cloth(const Program& prog) {
  buffer_texture(pos_tbo, part_pos, GL_RGB32F);  // the buffer may have been re-allocated
  glActiveTexture(GL_TEXTURE0), glBindTexture(GL_TEXTURE_BUFFER, pos_tbo);
  glActiveTexture(GL_TEXTURE1), glBindTexture(GL_TEXTURE_BUFFER, ring_off_tbo);
  glActiveTexture(GL_TEXTURE2), glBindTexture(GL_TEXTURE_BUFFER, ring_tbo);
  glActiveTexture(GL_TEXTURE3), glBindTexture(GL_TEXTURE_BUFFER, uv_tbo);
  glActiveTexture(GL_TEXTURE0);
  glUniform1i(prog.loc("u_pos"), 0);
  glUniform1i(prog.loc("u_ring_off"), 1);
  glUniform1i(prog.loc("u_ring"), 2);
  glUniform1i(prog.loc("u_uv"), 3);
  glUniform1i(prog.loc("u_first"), cloth_first);
}

void Renderer::Impl::draw_cloth(const RenderCamera& cam) {
  set_camera_uniforms(cloth_prog, cam);
  bind_cloth(cloth_prog);
  glUniform3f(cloth_prog.loc("u_tint"), p.cloth_color.x, p.cloth_color.y, p.cloth_color.z);
  glUniform1i(cloth_prog.loc("u_gingham"), p.cloth_pattern == ClothPattern::gingham);
  glUniform1f(cloth_prog.loc("u_sheen"), p.cloth_sheen);
  // Charlie alpha 0.5: a broad lobe (woven cotton); the sheen's colour is white (fibre surfaces).
  glUniform1f(cloth_prog.loc("u_sheen_roughness"), 0.5f);
  glBindVertexArray(cloth_vao);
  glDrawElements(GL_TRIANGLES, static_cast<GLsizei>(3 * cloth_tris.size()), GL_UNSIGNED_INT, nullptr);
  glBindVertexArray(0);
  glActiveTexture(GL_TEXTURE0);
}

void Renderer::Impl::draw_objects(const DrawList& list, std::int64_t n, const RenderCamera& cam) {
  if (p.show_rigid)
    for (const RigidDraw& r : list.rigids) {
      if (r.mesh) draw_mesh(body_mesh(r.mesh), cam, model_matrix(r.world_T_body), false, p.rigid_color, true);
      else draw_mesh(box, cam, model_matrix(r.world_T_body, r.half_extents), false, p.rigid_color, true);
    }
  if (p.show_cloth && n > 0)
    for (const ClothDraw& c : list.cloths) {
      if (c.triangles.empty()) continue;
      upload_cloth(c.triangles, n);
      draw_cloth(cam);
    }
  const bool fluid_as_particles = p.show_fluid && p.fluid == FluidDraw::particles;
  if (n > 0 && (p.show_particles || fluid_as_particles)) {
    const std::uint32_t mask = p.show_particles ? 0u : phase::kFluid;
    draw_spheres(particle_prog, n, mask, list.particle_radius, cam);
  }
}

void Renderer::Impl::draw_frame(const DrawList& list, std::int64_t n, const RenderCamera& cam) {
  timer.begin_frame();
  stages.clear();
  up = list.up;
  glViewport(0, 0, w, h);
  glBindFramebuffer(GL_FRAMEBUFFER, scene_fbo);
  const vec3 bg = p.background;
  glClearColor(bg.x, bg.y, bg.z, 1.f);
  glClearDepth(1.0);
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_LESS);
  glDepthMask(GL_TRUE);
  glDisable(GL_CULL_FACE);
  glDisable(GL_BLEND);
  glEnable(GL_PROGRAM_POINT_SIZE);
  glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
  shadow_pass(list, n);  // binds its own targets; the scene's are bound again below
  timer.mark("shadow");
  glBindFramebuffer(GL_FRAMEBUFFER, scene_fbo);
  glViewport(0, 0, w, h);
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_LESS);
  draw_scene(cam);
  timer.mark("scene");
  draw_objects(list, n, cam);
  timer.mark("objects");
  last_has_fluid = p.show_fluid && p.fluid == FluidDraw::ssfr && n > 0 && draw_fluid(n, list.particle_radius, cam);
  if (last_has_fluid && p.stage_images) capture_stages();
  // Submitted now, not waited for: the GPU renders while the host goes on to the next frame.
  glFlush();
  timings = timer.resolve_previous();
}

// ---------------------------------------------------------------------------------------------

namespace {

void init(Renderer::Impl& m, const RenderParams& params, int width, int height) {
  if (width < 1 || height < 1)
    throw Error("render: framebuffer size " + std::to_string(width) + "x" + std::to_string(height) +
                " is not positive (render.width / render.height)");
  m.p = params;
  m.w = width, m.h = height;
  m.build_programs();
  // Compute shaders and image atomics are core in GL 4.3.
  m.has_compute = epoxy_gl_version() >= 43;
  if (m.has_compute) m.build_compute_programs();
  else if (params.fluid_splat == FluidSplat::compute)
    spdlog::info("render: OpenGL {} has no compute shaders (4.3); fluid spheres are drawn as raster sprites",
                 epoxy_gl_version() / 10.0);
  m.build_shadow_programs();
  m.empty_vao = VertexArray(new_name(glGenVertexArrays));
  m.make_targets();
  m.make_box();
  m.part_vao = VertexArray(new_name(glGenVertexArrays));
  m.part_pos = GlBuffer(new_name(glGenBuffers));
  m.part_phase = GlBuffer(new_name(glGenBuffers));
  m.part_ell = GlBuffer(new_name(glGenBuffers));
  glBindVertexArray(m.part_vao);
  glBindBuffer(GL_ARRAY_BUFFER, m.part_pos);
  glEnableVertexAttribArray(0);
  glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, 0, nullptr);
  glBindBuffer(GL_ARRAY_BUFFER, m.part_phase);
  glEnableVertexAttribArray(1);
  glVertexAttribIPointer(1, 1, GL_UNSIGNED_INT, 0, nullptr);
  glBindVertexArray(0);
}

}  // namespace

Renderer::Renderer(const RenderParams& params, int width, int height) : impl_(std::make_unique<Impl>()) {
  impl_->ctx = std::make_unique<HeadlessContext>();
  impl_->info = impl_->ctx->info();
  init(*impl_, params, width, height);
}

Renderer::Renderer(const RenderParams& params, int width, int height, UseCurrentContext)
    : impl_(std::make_unique<Impl>()) {
  impl_->info.vendor = reinterpret_cast<const char*>(glGetString(GL_VENDOR));
  impl_->info.renderer = reinterpret_cast<const char*>(glGetString(GL_RENDERER));
  impl_->info.version = reinterpret_cast<const char*>(glGetString(GL_VERSION));
  init(*impl_, params, width, height);
}

Renderer::~Renderer() = default;

int Renderer::width() const { return impl_->w; }
int Renderer::height() const { return impl_->h; }
RenderParams& Renderer::params() { return impl_->p; }
const GlInfo& Renderer::gl_info() const { return impl_->info; }
const std::vector<StageImage>& Renderer::stage_images() const { return impl_->stages; }
const std::vector<RenderTiming>& Renderer::timings() const { return impl_->timings; }
std::vector<RenderTiming> Renderer::last_timings() { return impl_->timer.resolve(); }
bool Renderer::uses_compute_splat() const { return impl_->use_compute_splat(); }

Renderer::FluidImages Renderer::read_fluid_images() const {
  const Impl& m = *impl_;
  FluidImages f;
  f.w = m.w, f.h = m.h, f.tw = m.tw, f.th = m.th;
  f.depth = read_float(m.fluid_filter_fbo[0], 0, GL_RED, 1, m.w, m.h);
  f.thickness = read_float(m.thick_fbo[0], 0, GL_RED, 1, m.tw, m.th);
  return f;
}

unsigned Renderer::particle_position_buffer() const { return impl_->part_pos; }
unsigned Renderer::particle_phase_buffer() const { return impl_->part_phase; }
unsigned Renderer::particle_ellipsoid_buffer() const { return impl_->part_ell; }
std::optional<Renderer::EllipsoidSizes> Renderer::fluid_ellipsoid_sizes(float particle_radius) const {
  return impl_->ellipsoid_sizes(particle_radius);
}
void Renderer::use_device_ellipsoids(bool on) { impl_->ellipsoids_in_buffer = on; }

Renderer::OccluderCounts Renderer::fluid_occluder_counts() const {
  const Impl& m = *impl_;
  if (!m.has_compute || !m.occluder_passes) return {};
  GLuint c[2] = {0u, 0u};
  glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
  glBindBuffer(GL_SHADER_STORAGE_BUFFER, m.occluders);
  glGetBufferSubData(GL_SHADER_STORAGE_BUFFER, 0, sizeof(c), c);
  glBindBuffer(GL_SHADER_STORAGE_BUFFER, 0);
  return {c[0], c[1]};
}

void Renderer::resize(int width, int height) {
  if (width == impl_->w && height == impl_->h) return;
  if (width < 1 || height < 1) return;  // a minimised window
  impl_->w = width, impl_->h = height;
  impl_->make_targets();
}

void Renderer::set_scene_mesh(const Mesh& mesh) {
  Impl& m = *impl_;
  if (mesh.normals.size() != mesh.positions.size())
    throw Error("render: scene mesh has " + std::to_string(mesh.positions.size()) + " positions but " +
                std::to_string(mesh.normals.size()) + " normals");
  m.scene.upload(mesh.positions, mesh.normals, mesh.colors, mesh.triangles, GL_STATIC_DRAW);
  m.has_scene = !mesh.triangles.empty();
  const Box3 bounds = point_bounds(mesh.positions);
  m.scene_lo = bounds.lo, m.scene_hi = bounds.hi;
  m.render_cube_map();
}

void Renderer::set_kinect_view(const Image<uchar3>& rgb, const Image<float>& depth, const Intrinsics& K,
                               const SE3& world_T_camera, const PixelRect& colour_region) {
  Impl& m = *impl_;
  if (rgb.device() != Device::CPU || depth.device() != Device::CPU)
    throw Error("render: set_kinect_view takes host images (download them first)");
  if (rgb.width() != K.width || rgb.height() != K.height || depth.width() != K.width || depth.height() != K.height)
    throw Error("render: Kinect view images (rgb " + std::to_string(rgb.width()) + "x" + std::to_string(rgb.height()) +
                ", depth " + std::to_string(depth.width()) + "x" + std::to_string(depth.height()) +
                ") must both match the intrinsics' " + std::to_string(K.width) + "x" + std::to_string(K.height) +
                " (depth registered to rgb)");
  const PixelRect whole{0, 0, K.width, K.height};
  const PixelRect& r = colour_region.empty() ? whole : colour_region;
  if (r.x < 0 || r.y < 0 || r.x + r.width > K.width || r.y + r.height > K.height)
    throw Error("render: Kinect view colour region " + std::to_string(r.width) + "x" + std::to_string(r.height) +
                " at (" + std::to_string(r.x) + ", " + std::to_string(r.y) + ") is not inside the " +
                std::to_string(K.width) + "x" + std::to_string(K.height) + " image");
  if (!m.kin_rgb || m.kin_K.width != K.width || m.kin_K.height != K.height) {
    m.kin_rgb = make_texture_2d(GL_RGB8, K.width, K.height, GL_LINEAR);
    m.kin_depth = make_texture_2d(GL_R32F, K.width, K.height, GL_NEAREST);  // never blend depths
    for (GlBuffer& b : m.kin_pbo) b = GlBuffer(new_name(glGenBuffers));
  }
  upload_texture(m.kin_pbo[0], m.kin_rgb, K.width, K.height, GL_RGB, GL_UNSIGNED_BYTE, rgb.buffer().data(),
                 sizeof(uchar3));
  upload_texture(m.kin_pbo[1], m.kin_depth, K.width, K.height, GL_RED, GL_FLOAT, depth.buffer().data(), sizeof(float));
  m.kin_K = K;
  m.kin_region = r;
  m.kin_pose = world_T_camera;
  m.kin_mean = mean_linear_color(rgb.buffer().data(), K.width, r);
  m.has_kinect = true;
}

void Renderer::set_unmeasured_planes(const std::vector<vec4>& world_planes) {
  if (world_planes.size() > static_cast<std::size_t>(kMaxUnmeasuredPlanes))
    throw Error("render: " + std::to_string(world_planes.size()) + " unmeasured planes, at most " +
                std::to_string(kMaxUnmeasuredPlanes));
  for (const vec4& q : world_planes)
    if (std::abs(length(vec3{q.x, q.y, q.z}) - 1.f) > 1e-3f)
      throw Error("render: an unmeasured plane's normal must be a unit vector (plane n . x = w given as n, w)");
  impl_->kin_planes = world_planes;
}

RenderCamera Renderer::kinect_camera() const {
  const Impl& m = *impl_;
  RenderCamera c;
  c.K = m.has_kinect ? scale_intrinsics(crop_intrinsics(m.kin_K, fit_aspect(m.kin_region, m.w, m.h)), m.w, m.h)
                     : scale_intrinsics(Intrinsics{}, m.w, m.h);
  c.world_T_camera = m.kin_pose;
  c.znear = m.p.znear, c.zfar = m.p.zfar;
  return c;
}

namespace {
// The camera actually used: Kinect view overrides; a free camera's intrinsics must fit the target.
RenderCamera effective_camera(const Renderer& r, const RenderParams& p, const RenderCamera& cam) {
  if (p.view == RenderView::kinect) return r.kinect_camera();
  if (cam.K.width != r.width() || cam.K.height != r.height()) {
    RenderCamera c = cam;
    c.K = scale_intrinsics(cam.K, r.width(), r.height());
    return c;
  }
  return cam;
}
}  // namespace

void Renderer::draw(const DrawList& list, const RenderCamera& camera) {
  impl_->upload_particles(list);
  impl_->draw_frame(list, static_cast<std::int64_t>(list.positions.size()), effective_camera(*this, impl_->p, camera));
}

void Renderer::draw_device_particles(const DrawList& list, std::int64_t n, const RenderCamera& camera) {
  if (n > impl_->part_capacity)
    throw Error("render: " + std::to_string(n) + " device particles but the interop buffers hold " +
                std::to_string(impl_->part_capacity) + " (call reserve_particles first)");
  impl_->fluid_count = -1;
  impl_->aniso_live = impl_->ellipsoids_in_buffer && n > 0;
  impl_->draw_frame(list, n, effective_camera(*this, impl_->p, camera));
}

void Renderer::reserve_particles(std::int64_t n) {
  DrawList none;
  if (n <= impl_->part_capacity) return;
  std::vector<vec3> zeros(static_cast<std::size_t>(n), vec3{0, 0, 0});
  std::vector<std::uint32_t> ph(static_cast<std::size_t>(n), 0u);
  none.positions = zeros;
  none.phases = ph;
  impl_->upload_particles(none);
}

Image<uchar3> Renderer::read_frame() {
  const Impl& m = *impl_;
  return read_rgb8(m.last_has_fluid ? m.final_fbo : m.scene_fbo, 0, m.w, m.h);
}

Image<uchar3> Renderer::render(const DrawList& list, const RenderCamera& camera) {
  draw(list, camera);
  return read_frame();
}

void Renderer::blit_to(unsigned framebuffer, int w, int h) {
  const Impl& m = *impl_;
  glBindFramebuffer(GL_READ_FRAMEBUFFER, m.last_has_fluid ? m.final_fbo : m.scene_fbo);
  glReadBuffer(GL_COLOR_ATTACHMENT0);
  glBindFramebuffer(GL_DRAW_FRAMEBUFFER, framebuffer);
  glBlitFramebuffer(0, 0, m.w, m.h, 0, 0, w, h, GL_COLOR_BUFFER_BIT, GL_LINEAR);
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
}

}  // namespace seamless
