// GL object helpers of renderer_impl.hpp.
#include <algorithm>

#include "core/error.hpp"
#include "render/renderer_impl.hpp"

namespace seamless {

void gl_delete_texture(GLuint id) { glDeleteTextures(1, &id); }
void gl_delete_buffer(GLuint id) { glDeleteBuffers(1, &id); }
void gl_delete_framebuffer(GLuint id) { glDeleteFramebuffers(1, &id); }
void gl_delete_renderbuffer(GLuint id) { glDeleteRenderbuffers(1, &id); }
void gl_delete_vertex_array(GLuint id) { glDeleteVertexArrays(1, &id); }

GLuint new_name(void (*gen)(GLsizei, GLuint*)) {
  GLuint id = 0;
  gen(1, &id);
  return id;
}

Texture make_texture_2d(GLenum internal, int w, int h, GLenum filter) {
  Texture t(new_name(glGenTextures));
  glBindTexture(GL_TEXTURE_2D, t);
  glTexStorage2D(GL_TEXTURE_2D, 1, internal, w, h);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, static_cast<GLint>(filter));
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, static_cast<GLint>(filter));
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
  return t;
}

Framebuffer make_framebuffer(const std::vector<GLuint>& colors, GLuint depth, const char* what) {
  Framebuffer f(new_name(glGenFramebuffers));
  glBindFramebuffer(GL_FRAMEBUFFER, f);
  std::vector<GLenum> bufs;
  for (std::size_t i = 0; i < colors.size(); ++i) {
    const GLenum a = GL_COLOR_ATTACHMENT0 + static_cast<GLenum>(i);
    glFramebufferTexture2D(GL_FRAMEBUFFER, a, GL_TEXTURE_2D, colors[i], 0);
    bufs.push_back(a);
  }
  if (depth) glFramebufferTexture2D(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_TEXTURE_2D, depth, 0);
  glDrawBuffers(static_cast<GLsizei>(bufs.size()), bufs.data());
  const GLenum st = glCheckFramebufferStatus(GL_FRAMEBUFFER);
  if (st != GL_FRAMEBUFFER_COMPLETE)
    throw Error(std::string("render: framebuffer '") + what + "' is incomplete (status " + std::to_string(st) +
                "); the driver lacks a needed render target format");
  return f;
}

std::vector<float> read_float(GLuint fbo, int attachment, GLenum format, int channels, int w, int h) {
  std::vector<float> v(static_cast<std::size_t>(w) * h * channels);
  glBindFramebuffer(GL_READ_FRAMEBUFFER, fbo);
  glReadBuffer(GL_COLOR_ATTACHMENT0 + static_cast<GLenum>(attachment));
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glReadPixels(0, 0, w, h, format, GL_FLOAT, v.data());
  return v;
}

Image<uchar3> read_rgb8(GLuint fbo, int attachment, int w, int h) {
  std::vector<uchar3> raw(static_cast<std::size_t>(w) * h);
  glBindFramebuffer(GL_READ_FRAMEBUFFER, fbo);
  glReadBuffer(GL_COLOR_ATTACHMENT0 + static_cast<GLenum>(attachment));
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glReadPixels(0, 0, w, h, GL_RGB, GL_UNSIGNED_BYTE, raw.data());
  std::vector<uchar3> flipped(raw.size());  // GL rows run bottom to top
  for (int y = 0; y < h; ++y)
    std::copy_n(raw.begin() + static_cast<std::ptrdiff_t>(y) * w, w,
                flipped.begin() + static_cast<std::ptrdiff_t>(h - 1 - y) * w);
  return Image<uchar3>::from_host(flipped, w, h, Device::CPU);
}

void GlMesh::upload(const std::vector<vec3>& p, const std::vector<vec3>& n, const std::vector<uchar3>& c,
                    const std::vector<int3>& tris, GLenum usage) {
  if (!vao) {
    vao = VertexArray(new_name(glGenVertexArrays));
    pos = GlBuffer(new_name(glGenBuffers)), nrm = GlBuffer(new_name(glGenBuffers));
    col = GlBuffer(new_name(glGenBuffers)), idx = GlBuffer(new_name(glGenBuffers));
  }
  glBindVertexArray(vao);
  auto attrib = [&](GLuint buf, GLuint loc, const void* data, std::size_t bytes, GLint k, GLenum type, bool norm) {
    glBindBuffer(GL_ARRAY_BUFFER, buf);
    glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(bytes), data, usage);
    glEnableVertexAttribArray(loc);
    glVertexAttribPointer(loc, k, type, norm ? GL_TRUE : GL_FALSE, 0, nullptr);
  };
  attrib(pos, 0, p.data(), p.size() * sizeof(vec3), 3, GL_FLOAT, false);
  attrib(nrm, 1, n.data(), n.size() * sizeof(vec3), 3, GL_FLOAT, false);
  if (c.size() == p.size()) {
    attrib(col, 2, c.data(), c.size() * sizeof(uchar3), 3, GL_UNSIGNED_BYTE, true);
  } else {
    glDisableVertexAttribArray(2);
    glVertexAttrib3f(2, 0.7f, 0.7f, 0.7f);  // a mesh without colours is grey
  }
  glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, idx);
  glBufferData(GL_ELEMENT_ARRAY_BUFFER, static_cast<GLsizeiptr>(tris.size() * sizeof(int3)), tris.data(), usage);
  index_count = static_cast<GLsizei>(tris.size() * 3);
  glBindVertexArray(0);
}

void GlMesh::draw() const {
  if (!vao || index_count == 0) return;
  glBindVertexArray(vao);
  glDrawElements(GL_TRIANGLES, index_count, GL_UNSIGNED_INT, nullptr);
  glBindVertexArray(0);
}

void PassTimer::begin_frame() {
  current_ = 1 - current_;
  frames_[current_].used = 0;
  frames_[current_].names.clear();
  mark("");
}

void PassTimer::mark(const char* pass) {
  Frame& f = frames_[current_];
  if (f.used == f.queries.size()) f.queries.push_back(new_name([](GLsizei n, GLuint* q) { glGenQueries(n, q); }));
  glQueryCounter(f.queries[f.used++], GL_TIMESTAMP);
  f.names.emplace_back(pass);
}

std::vector<RenderTiming> PassTimer::read(const Frame& f) {
  std::vector<RenderTiming> out;
  GLuint64 prev = 0;
  for (std::size_t i = 0; i < f.used; ++i) {
    GLuint64 t = 0;
    glGetQueryObjectui64v(f.queries[i], GL_QUERY_RESULT, &t);
    if (i > 0) out.push_back({f.names[i], static_cast<double>(t - prev) * 1e-6});
    prev = t;
  }
  return out;
}

std::vector<RenderTiming> PassTimer::resolve() { return read(frames_[current_]); }

std::vector<RenderTiming> PassTimer::resolve_previous() { return read(frames_[1 - current_]); }

PassTimer::~PassTimer() {
  for (const Frame& f : frames_)
    if (!f.queries.empty()) glDeleteQueries(static_cast<GLsizei>(f.queries.size()), f.queries.data());
}

}  // namespace seamless
