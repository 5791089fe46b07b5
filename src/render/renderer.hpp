// One renderer, two front ends (docs/RENDERING.md). It draws into its own framebuffer objects:
// the headless front end reads frames back (PNG, video), the window blits them to the screen.
//
//   Renderer r(params, 640, 480);                 // creates a headless EGL context
//   r.set_scene_mesh(mesh);                       // or r.set_kinect_view(rgb, depth, K, pose)
//   r.draw(make_draw_list(state, solver.objects(), solver.rigid_frames(), radius), camera);
//   Image<uchar3> img = r.read_frame();
//
// Passes: scene (mesh or Kinect image + depth), rigid boxes, cloth, debug particle spheres,
// then screen-space fluid rendering (van der Laan, Green, Sainz 2009) over the result.
#pragma once
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "core/buffer.hpp"
#include "core/intrinsics.hpp"
#include "core/math.hpp"
#include "render/draw_list.hpp"
#include "render/gl_context.hpp"
#include "render/render_camera.hpp"
#include "render/render_params.hpp"

namespace seamless {

// An intermediate image of the fluid renderer, made viewable (depth as grey, normals as colour).
struct StageImage {
  std::string name;  // "1_depth", "2_depth_filtered", "3_normals", "4_thickness", ...
  Image<uchar3> image;
};

struct RenderTiming {
  std::string pass;
  double ms;
};

class Renderer {
 public:
  struct UseCurrentContext {};
  // Creates and owns a headless EGL context (throws seamless::Error if none can be made).
  Renderer(const RenderParams& params, int width, int height);
  // Uses the context current on this thread (the window front end's).
  Renderer(const RenderParams& params, int width, int height, UseCurrentContext);
  ~Renderer();
  Renderer(const Renderer&) = delete;
  Renderer& operator=(const Renderer&) = delete;

  int width() const;
  int height() const;
  void resize(int width, int height);
  RenderParams& params();
  const GlInfo& gl_info() const;  // vendor/renderer (EGL path empty when not owned)

  // The reconstructed scene (mesh view). Also renders the reflection cube map from the centre
  // of the mesh's bounding box (dissertation 4.3.5: a camera in the middle of the scene).
  void set_scene_mesh(const Mesh& mesh);
  // The Kinect's point of view: RGB image and its registered depth (metres, 0 = none) with the
  // exact intrinsics of both and the tracked pose (x right, y down, z forward). The frame shows
  // the part colour_region of the image (empty: all of it; RgbdFrame::colour_region leaves out
  // undistortion's black border), cut to the framebuffer's aspect ratio.
  void set_kinect_view(const Image<uchar3>& rgb, const Image<float>& depth, const Intrinsics& K,
                       const SE3& world_T_camera, const PixelRect& colour_region = {});
  // Surfaces the camera did not measure, as planes n . x = w in the world (n a unit vector; at most
  // kMaxUnmeasuredPlanes): in the Kinect view a pixel without recorded depth whose ray meets one
  // in front of the camera takes the nearest such point as its real surface, which then hides what
  // lies behind it and receives the virtual objects' shadows (a table top the Kinect returned no
  // depth from, `support_plane`; the floor plane where its readings are missing). Empty (the
  // default): such pixels stay empty, nothing there hides or receives anything.
  static constexpr int kMaxUnmeasuredPlanes = 4;
  void set_unmeasured_planes(const std::vector<vec4>& world_planes);
  // The camera the Kinect view draws with: K cropped to the part shown and scaled to the
  // framebuffer, the tracked pose.
  RenderCamera kinect_camera() const;

  // Draws one frame. In the Kinect view (params().view == RenderView::kinect) `camera` is ignored and
  // kinect_camera() is used, so that the virtual objects line up with the image.
  void draw(const DrawList& list, const RenderCamera& camera);
  // The last frame, rows top to bottom.
  Image<uchar3> read_frame();
  // draw + read_frame.
  Image<uchar3> render(const DrawList& list, const RenderCamera& camera);
  // Fluid stages of the last draw when params().stage_images is set (empty without fluid).
  const std::vector<StageImage>& stage_images() const;
  // GPU time of each pass of the draw before the last one (empty after the first draw): a draw
  // does not wait for its own passes, whose timer queries the GPU answers only when it has done
  // them, and reads the previous draw's instead (by then done). Frames drawn alike (benchmarks)
  // have the same passes; last_timings() has the last draw's.
  const std::vector<RenderTiming>& timings() const;
  // GPU time of each pass of the last draw: waits for the GPU to finish it (the end of a run).
  std::vector<RenderTiming> last_timings();
  // The fluid's float images of the last draw (rows bottom to top): eye depth after the filter
  // (0 = no fluid; with render.filter_iterations 0 the spheres' own depth) at the framebuffer
  // size, and the thickness in metres after its blur at 1/thickness_downsample. For tests.
  struct FluidImages {
    std::vector<float> depth, thickness;
    int w = 0, h = 0, tw = 0, th = 0;
  };
  FluidImages read_fluid_images() const;
  // The last draw's fluid depth splat in two passes (render.fluid_occluders): the particles it
  // splatted first as occluders, and how many of the others it skipped as hidden behind them;
  // zeros after a splat in one pass. Waits for the GPU. For tests.
  struct OccluderCounts {
    std::int64_t occluders = 0, skipped = 0;
  };
  OccluderCounts fluid_occluder_counts() const;
  // Whether the fluid sphere passes run as compute splats (render.fluid_splat: compute and GL 4.3).
  bool uses_compute_splat() const;
  // Copies the last frame to the bound draw framebuffer (0 = the window), scaled to w x h.
  void blit_to(unsigned framebuffer, int w, int h);
  // The particle position/phase buffers for CUDA-OpenGL interop (render/cuda_interop.hpp), and
  // the fluid's ellipsoids (FluidEllipsoids::kVec4s vec4 per particle).
  unsigned particle_position_buffer() const;
  unsigned particle_phase_buffer() const;
  unsigned particle_ellipsoid_buffer() const;
  // The anisotropic kernels' sizes for particles of this radius (FluidEllipsoids::compute's radius
  // and h): the sphere drawn and the neighbourhood (FluidEllipsoids::kNeighbourhoodRadii radii: two rest
  // spacings). None when the fluid is drawn as spheres (render.fluid_anisotropy off, or no
  // compute splats).
  struct EllipsoidSizes {
    float radius = 0.f, h = 0.f;
  };
  std::optional<EllipsoidSizes> fluid_ellipsoid_sizes(float particle_radius) const;
  // Whether the next draw_device_particles splats the ellipsoids in particle_ellipsoid_buffer()
  // (the interop filled it) or spheres. A host draw sets it too: whether it uploaded ellipsoids.
  void use_device_ellipsoids(bool on);
  // Makes the particle buffers hold at least n particles (before registering them for interop).
  void reserve_particles(std::int64_t n);
  // Draws with particles already in particle_*_buffer() (n of them) instead of list.positions.
  void draw_device_particles(const DrawList& list, std::int64_t n, const RenderCamera& camera);

  struct Impl;

 private:
  std::unique_ptr<Impl> impl_;
};

// Turns a float image into grey (min..max of the non-zero values to 0..255; zero stays black),
// as the stage images do. Exposed for tests.
Image<uchar3> float_to_grey(const std::vector<float>& v, int width, int height);

}  // namespace seamless
