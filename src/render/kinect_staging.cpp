// KinectStaging: the Kinect view's images copied into pixel buffers by a worker thread
// (Renderer::stage_kinect_images). In the live loop the host's copy of the recorded frame was most
// of the render stage's host time, while the host waited on the GPU's tracking just before
// (docs/PERFORMANCE.md, "The live AR loop"); staged right after the frame is read, the copy
// overlaps that wait. Only the worker touches the buffer's mapped memory, only the GL thread
// calls GL.
#include <spdlog/spdlog.h>

#include <atomic>
#include <cstring>

#include "render/renderer_impl.hpp"

namespace seamless {

namespace {

// Pixel-buffer offsets must be multiples of the texel type's size (a float for depth); whole cache
// lines keep the worker's writes of the two images and the two halves apart.
constexpr std::size_t kAlign = 64;
std::size_t aligned(std::size_t n) { return (n + kAlign - 1) / kAlign * kAlign; }

// Waits until the GPU has passed `fence` (the last texture upload from a half) and deletes it.
void wait_and_delete(GLsync& fence) {
  if (!fence) return;
  constexpr GLuint64 kTimeoutNs = 1'000'000'000;
  for (;;) {
    const GLenum s = glClientWaitSync(fence, GL_SYNC_FLUSH_COMMANDS_BIT, kTimeoutNs);
    if (s == GL_ALREADY_SIGNALED || s == GL_CONDITION_SATISFIED) break;
    if (s == GL_WAIT_FAILED) {
      glDeleteSync(fence);
      fence = nullptr;
      throw Error("render: waiting for the Kinect view's pixel buffer failed (glClientWaitSync)");
    }
  }
  glDeleteSync(fence);
  fence = nullptr;
}

}  // namespace

KinectStaging::~KinectStaging() {
  drop();
  for (GLsync& f : fence_)
    if (f) glDeleteSync(f);
  // Deleting the buffer (its GlBuffer, after this) unmaps it.
}

bool KinectStaging::supported() {
  if (supported_) return *supported_;
  supported_ = epoxy_gl_version() >= 44 || epoxy_has_gl_extension("GL_ARB_buffer_storage");
  static std::atomic<bool> logged{false};
  if (!*supported_ && !logged.exchange(true))
    spdlog::info(
        "render: OpenGL {} has no persistently mapped buffers (4.4 or ARB_buffer_storage); the Kinect view's "
        "images are copied when they are set",
        epoxy_gl_version() / 10.0);
  return *supported_;
}

void KinectStaging::reserve(std::size_t half_bytes) {
  if (half_bytes <= half_bytes_) return;
  // The old buffer goes at once: GL keeps its storage until the GPU has read it.
  for (GLsync& f : fence_) {
    if (f) glDeleteSync(f);
    f = nullptr;
  }
  buf_ = GlBuffer(new_name(glGenBuffers));
  const GLbitfield flags = GL_MAP_WRITE_BIT | GL_MAP_PERSISTENT_BIT | GL_MAP_COHERENT_BIT;
  glBindBuffer(GL_PIXEL_UNPACK_BUFFER, buf_);
  glBufferStorage(GL_PIXEL_UNPACK_BUFFER, static_cast<GLsizeiptr>(2 * half_bytes), nullptr, flags);
  map_ = static_cast<unsigned char*>(
      glMapBufferRange(GL_PIXEL_UNPACK_BUFFER, 0, static_cast<GLsizeiptr>(2 * half_bytes), flags));
  glBindBuffer(GL_PIXEL_UNPACK_BUFFER, 0);
  if (!map_) {
    buf_ = GlBuffer();
    half_bytes_ = 0;
    throw Error("render: cannot map the Kinect view's pixel buffer (glMapBufferRange)");
  }
  half_bytes_ = half_bytes;
}

bool KinectStaging::start(const Image<uchar3>& rgb, const Image<float>& depth, const PixelRect& colour_region) {
  drop();
  const int w = rgb.width(), h = rgb.height();
  const PixelRect r = colour_region.empty() ? PixelRect{0, 0, w, h} : colour_region;
  // Images set_kinect_view would refuse are not staged: it then says why.
  if (rgb.device() != Device::CPU || depth.device() != Device::CPU || depth.width() != w || depth.height() != h ||
      w < 1 || h < 1 || r.x < 0 || r.y < 0 || r.x + r.width > w || r.y + r.height > h || !supported())
    return false;
  const auto texels = static_cast<std::size_t>(w) * h;
  const std::size_t depth_at = aligned(texels * sizeof(uchar3));
  reserve(aligned(depth_at + texels * sizeof(float)));
  wait_and_delete(fence_[next_]);  // the GPU has read this half's last images
  unsigned char* dst = map_ + static_cast<std::size_t>(next_) * half_bytes_;
  const uchar3* src_rgb = rgb.buffer().data();
  const float* src_depth = depth.buffer().data();
  staged_ = Staged{src_rgb, src_depth, w, h, r, next_, depth_at};
  worker_ = std::async(std::launch::async, [=] {
    std::memcpy(dst, src_rgb, texels * sizeof(uchar3));
    std::memcpy(dst + depth_at, src_depth, texels * sizeof(float));
    return mean_linear_color(src_rgb, w, r);
  });
  next_ = 1 - next_;
  return true;
}

std::optional<vec3> KinectStaging::finish(const Image<uchar3>& rgb, const Image<float>& depth,
                                          const PixelRect& colour_region, GLuint rgb_tex, GLuint depth_tex) {
  if (!staged_) return std::nullopt;
  const Staged s = *staged_;
  const int w = rgb.width(), h = rgb.height();
  const PixelRect r = colour_region.empty() ? PixelRect{0, 0, w, h} : colour_region;
  if (s.rgb != rgb.buffer().data() || s.depth != depth.buffer().data() || s.w != w || s.h != h || s.region.x != r.x ||
      s.region.y != r.y || s.region.width != r.width || s.region.height != r.height) {
    drop();  // other images than those staged: set synchronously
    return std::nullopt;
  }
  staged_.reset();
  const vec3 mean = worker_.get();  // rethrows the worker's exception
  const std::size_t at = static_cast<std::size_t>(s.half) * half_bytes_;
  glBindBuffer(GL_PIXEL_UNPACK_BUFFER, buf_);
  glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
  glBindTexture(GL_TEXTURE_2D, rgb_tex);
  glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, w, h, GL_RGB, GL_UNSIGNED_BYTE, reinterpret_cast<const void*>(at));
  glBindTexture(GL_TEXTURE_2D, depth_tex);
  glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, w, h, GL_RED, GL_FLOAT, reinterpret_cast<const void*>(at + s.depth_at));
  glBindBuffer(GL_PIXEL_UNPACK_BUFFER, 0);
  fence_[s.half] = glFenceSync(GL_SYNC_GPU_COMMANDS_COMPLETE, 0);
  return mean;
}

void KinectStaging::drop() noexcept {
  staged_.reset();
  if (!worker_.valid()) return;
  try {
    worker_.get();
  } catch (const std::exception& e) {
    spdlog::warn("render: a staged Kinect image copy failed ({}); it was not used", e.what());
  }
}

}  // namespace seamless
