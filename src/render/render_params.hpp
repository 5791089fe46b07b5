// Render section (`render:`): window / headless output, what to draw and what to write.
// docs/RENDERING.md explains every key and the passes they tune.
#pragma once
#include <string>
#include <vector>

#include "core/error.hpp"
#include "core/math.hpp"
#include "core/params.hpp"

namespace seamless {

enum class RenderMode { window, headless, none };
inline std::span<const EnumName<RenderMode>> enum_names(RenderMode) {
  static constexpr EnumName<RenderMode> names[] = {
      {RenderMode::window, "window"}, {RenderMode::headless, "headless"}, {RenderMode::none, "none"}};
  return names;
}
enum class RenderView { mesh, kinect };
inline std::span<const EnumName<RenderView>> enum_names(RenderView) {
  static constexpr EnumName<RenderView> names[] = {{RenderView::mesh, "mesh"}, {RenderView::kinect, "kinect"}};
  return names;
}
enum class RenderCameraMode { fixed, recorded };
inline std::span<const EnumName<RenderCameraMode>> enum_names(RenderCameraMode) {
  static constexpr EnumName<RenderCameraMode> names[] = {{RenderCameraMode::fixed, "fixed"},
                                                         {RenderCameraMode::recorded, "recorded"}};
  return names;
}
enum class FluidDraw { ssfr, particles };
inline std::span<const EnumName<FluidDraw>> enum_names(FluidDraw) {
  static constexpr EnumName<FluidDraw> names[] = {{FluidDraw::ssfr, "ssfr"}, {FluidDraw::particles, "particles"}};
  return names;
}
enum class ClothPattern { gingham, plain };
inline std::span<const EnumName<ClothPattern>> enum_names(ClothPattern) {
  static constexpr EnumName<ClothPattern> names[] = {{ClothPattern::gingham, "gingham"},
                                                     {ClothPattern::plain, "plain"}};
  return names;
}
enum class FluidFilter { narrow_range, bilateral };
inline std::span<const EnumName<FluidFilter>> enum_names(FluidFilter) {
  static constexpr EnumName<FluidFilter> names[] = {{FluidFilter::narrow_range, "narrow_range"},
                                                    {FluidFilter::bilateral, "bilateral"}};
  return names;
}
enum class FluidSplat { compute, raster };
inline std::span<const EnumName<FluidSplat>> enum_names(FluidSplat) {
  static constexpr EnumName<FluidSplat> names[] = {{FluidSplat::compute, "compute"}, {FluidSplat::raster, "raster"}};
  return names;
}

struct RenderParams {
  RenderMode mode = RenderMode::none;
  int width = 1280;
  int height = 720;
  RenderView view = RenderView::mesh;  // mesh: coloured scene mesh; kinect: live RGB with depth occlusion
  // fixed: the mesh view from behind and above the first camera, the Kinect view from the first
  // frame; recorded: output frame k is recorded frame k seen from its tracked pose, the simulation
  // advancing by the recording's frame interval (scan_then_simulate replays the recording after the scan).
  RenderCameraMode camera = RenderCameraMode::fixed;
  int replay_start = 0;  // recorded, scan_then_simulate: first input frame of the replay
  // recorded, mesh view: magnify the recorded camera about pixel zoom_at (default the centre), so
  // that a figure can frame an object that the recording saw from afar (a chair across the room).
  float zoom = 1.f;
  std::vector<float> zoom_at;
  FluidDraw fluid = FluidDraw::ssfr;  // screen-space fluid rendering (van der Laan 2009) or raw particles
  bool write_frames = false;
  bool video = false;
  bool stage_images = false;
  // Camera of the mesh view (the Kinect view uses the sensor's intrinsics and tracked pose).
  float fov_y = 60.f;  // degrees, vertical
  // Where the fixed mesh-view camera stands and what it looks at (world metres, [x, y, z]); empty:
  // behind and above the first scanning camera, looking at the scanned mesh's centre. A camera that
  // sees only what the scan saw shows no empty background (the demo frames the desk this way).
  std::vector<float> eye, target;
  // The fixed mesh-view camera turns by this many degrees about the vertical through the target
  // between the first and the last frame of a run (parallax that shows depth); 0: it stays.
  float orbit_deg = 0.f;
  float znear = 0.05f, zfar = 30.f;  // metres
  int fps = 30;                      // video frame rate
  // What is drawn (the window toggles these with keys 1-5).
  bool show_scene = true, show_fluid = true, show_rigid = true, show_cloth = true;
  bool show_particles = false;  // every dynamic particle as a sphere impostor (debug view)
  // Shading.
  vec3 background{0.12f, 0.13f, 0.15f};  // clear colour of the mesh view, linear 0..1
  vec3 light_dir{0.3f, -1.f, 0.4f};      // direction the light travels, world coordinates
  float ambient = 0.3f;                  // fraction of light that is not directional
  bool light_scene = false;              // the scan's colours already hold the room's lighting
  // Shadows of the virtual objects on the real scene and on each other (docs/RENDERING.md, pass
  // shadow): a shadow map along light_dir over the dynamic objects' bounds.
  bool shadows = true;
  float shadow_strength = 0.5f;  // share of a real surface's light that light_dir brings (darkening)
  int shadow_map_size = 2048;    // texels per side
  float light_angle = 10.f;      // the light's angular diameter, degrees: penumbra growth
  vec3 rigid_color{0.85f, 0.3f, 0.2f};
  vec3 cloth_color{0.6f, 0.1f, 0.12f};
  // The dye over the sheet's particle grid: gingham (two-cell bands of cloth_color over white, so
  // that the folds and the fabric's scale read) or plain cloth_color.
  ClothPattern cloth_pattern = ClothPattern::gingham;
  float cloth_sheen = 0.4f;  // fabric sheen (Charlie BRDF) reflectance: the bright rim of folds seen edge-on
  // Screen-space fluid rendering (van der Laan, Green, Sainz 2009).
  // Spheres of the fluid passes are drawn this much larger than the particle radius: at rest the
  // particles sit about one diameter apart, and on a cubic lattice seen face-on the gaps between
  // four touching spheres close only above sqrt(2) (the gap centre is sqrt(2) r from each).
  float fluid_radius_scale = 1.5f;
  FluidFilter fluid_filter =
      FluidFilter::narrow_range;  // depth smoothing: narrow_range (Truong & Yuksel 2018) or bilateral
  int filter_iterations = 2;      // separable filter iterations over the depth (rows and columns, alternating order)
  int filter_max_taps = 12;       // taps per side at most: wider kernels sample every k-th pixel
  // Filter half-width in particle radii (world), projected per pixel: three particle spacings
  // (a diameter each), so that the spheres' bumps average out into one surface.
  float filter_size = 6.f;
  int filter_max_px = 24;          // ... but at most this many pixels
  float filter_depth_sigma = 1.f;  // range sigma of the bilateral filter, in particle radii
  // Gap fill of the depth before smoothing: empty runs between fluid pixels up to this many
  // particle radii wide (world, at their depth) and at one depth become fluid (0: off). Spheres
  // only: with the anisotropic kernels the layer is closed by its ellipsoids.
  float fluid_gap_fill = 4.f;
  // Anisotropic kernels (Yu & Turk 2013): each fluid particle splatted as an ellipsoid shaped by
  // its neighbours within two rest spacings (compute splats only; the raster path draws spheres).
  bool fluid_anisotropy = true;
  // The fluid's depth splat in two passes when the anisotropic kernels mark the particles at the
  // surface: those first, then the others, each skipped when the depth already splatted hides it
  // across its whole footprint (the same image bit for bit; docs/RENDERING.md, Speed).
  bool fluid_occluders = true;
  vec3 absorption{2.f, 0.7f, 0.35f};  // Beer-Lambert coefficients per colour channel, 1/m (docs/RENDERING.md, Water)
  float ior = 1.33f;                  // refractive index (water): Snell's law bends the view into the fluid
  float fresnel_f0 = 0.02f;           // reflectance at normal incidence (water: ((1-1.33)/(1+1.33))^2)
  float fluid_roughness = 0.05f;      // GGX alpha of the fluid surface: size of the light's highlight
  float light_intensity =
      0.6f;             // radiance light_dir alone gives a white diffuse surface facing it (0..1 = black..white)
  int cube_size = 256;  // cube map face size for reflections in the mesh view
  // Screen-space reflection: the reflected ray is marched over ssr_distance metres in ssr_steps
  // steps against the scene depth (0 steps: the environment alone).
  int ssr_steps = 24;
  float ssr_distance = 1.5f;
  // Water resting on a surface darkens it, as a wet surface is (Lekner & Dorf 1988).
  bool fluid_wet = true;
  // Cost of the fluid passes (docs/RENDERING.md, section Speed).
  // compute: sphere depth and thickness as compute splats (GL 4.3; atomics into integer images)
  // and the full-screen passes as compute shaders; raster: point sprites and full-screen
  // triangles. Compute is the default because GH100 (H100/H200) keeps raster units on only a few
  // of its SMs; a context below GL 4.3 falls back to raster.
  FluidSplat fluid_splat = FluidSplat::compute;
  int thickness_downsample = 2;  // thickness pass and its blur at 1/this resolution (1, 2 or 4), bilinear up
  bool depth_prepass = true;     // hardware depth test of the sprites against the scene depth (early-Z)
  float max_point_size = 64.f;   // sprite size limit, pixels: nearer spheres are cut to this square
  bool cuda_interop = true;      // CUDA runs: copy particles device to device into GL (no host trip)

  // Rules across keys, checked when a config is loaded (Experiment::validate).
  void validate() const {
    std::vector<std::string> problems;
    check(problems);
    if (!problems.empty()) throw ConfigError(problems.front());
  }
  // The same, every problem appended to `problems` (config loading lists them all at once).
  void check(std::vector<std::string>& problems) const {
    for (const auto& [key, xyz] : {std::pair{"eye", &eye}, std::pair{"target", &target}})
      if (!xyz->empty() && xyz->size() != 3)
        problems.push_back(std::string("render.") + key + ": expected [x, y, z] (three numbers, world metres), got " +
                           std::to_string(xyz->size()));
    if (eye.size() == 3 && target.size() == 3 && eye == target)
      problems.push_back("render.eye and render.target are the same point: the camera would look nowhere");
    // zoom / zoom_at crop the recorded camera of the mesh view (app/render_stage.cpp); elsewhere they
    // would be ignored silently.
    if (!zoom_at.empty() && zoom_at.size() != 2)
      problems.push_back("render.zoom_at: expected [u, v] (two numbers), got " + std::to_string(zoom_at.size()));
    if ((zoom != 1.f || !zoom_at.empty()) && (camera != RenderCameraMode::recorded || view != RenderView::mesh))
      problems.push_back(
          "render.zoom and render.zoom_at magnify the recorded camera of the mesh view; they need "
          "render.camera: recorded and render.view: mesh (the mesh view's fixed camera has render.fov_y)");
  }

  template <class V> void visit(V& v) {
    v("mode", mode, "window, headless (PNGs) or no rendering");
    v("width", width, "framebuffer width, pixels", Range{16, 16384});
    v("height", height, "framebuffer height, pixels", Range{16, 16384});
    v("view", view, "scene as reconstructed mesh or as the Kinect's view");
    v("camera", camera,
      "fixed: one viewpoint (mesh: behind the first camera; kinect: the first frame); recorded: replay the "
      "recording, output frame k = input frame k from its tracked pose, simulation in the recording's time");
    v("replay_start", replay_start, "camera recorded, scan_then_simulate: input frame the replay starts at",
      Range{0, 1e9});
    v("zoom", zoom, "camera recorded, view mesh: magnify the recorded camera this many times about zoom_at",
      Range{1.0, 20.0});
    v("zoom_at", zoom_at, "[u, v]: input image pixel that zoom centres on (empty: the image centre)", Range{-1e5, 1e5});
    v("fluid", fluid, "fluid drawing");
    v("write_frames", write_frames, "write each rendered frame as PNG into the output folder");
    v("video", video, "encode the frames into a video (needs ffmpeg)");
    v("stage_images", stage_images, "also write the intermediate SSFR stages (depth, blur, thickness)");
    v("fov_y", fov_y, "vertical field of view of the mesh view camera, degrees", Range{5.0, 170.0});
    v("eye", eye,
      "[x, y, z]: position of the fixed mesh view camera, world metres; empty: behind and above the "
      "first scanning camera",
      Range{-1e4, 1e4});
    v("target", target,
      "[x, y, z]: point the fixed mesh view camera looks at, world metres; empty: the scanned "
      "mesh's centre",
      Range{-1e4, 1e4});
    v("orbit_deg", orbit_deg,
      "the fixed mesh view camera turns this many degrees about the vertical through its "
      "target from the first frame to the last; 0: it stays",
      Range{-360.0, 360.0});
    v("znear", znear, "near clipping distance, metres", Range{1e-4, 10.0});
    v("zfar", zfar, "far clipping distance, metres", Range{0.1, 1e5});
    v("fps", fps, "frame rate of the encoded video", Range{1, 240});
    v("show_scene", show_scene, "draw the scene (mesh or Kinect image)");
    v("show_fluid", show_fluid, "draw fluid particles");
    v("show_rigid", show_rigid, "draw rigid bodies");
    v("show_cloth", show_cloth, "draw cloth");
    v("show_particles", show_particles, "draw every dynamic particle as a sphere (debug)");
    v("background", background, "clear colour of the mesh view, RGB 0..1");
    v("light_dir", light_dir, "direction the light travels, world coordinates");
    v("ambient", ambient, "ambient fraction of the lighting", Range{0.0, 1.0});
    v("light_scene", light_scene, "also light the scene mesh (its colours already contain lighting)");
    v("shadows", shadows, "virtual objects cast shadows (on the scene and on each other) from light_dir");
    v("shadow_strength", shadow_strength,
      "darkening of the real scene in full shadow: the share of its light that comes from light_dir", Range{0.0, 1.0});
    v("shadow_map_size", shadow_map_size, "shadow map texels per side (over the dynamic objects)", Range{64, 16384});
    v("light_angle", light_angle, "angular diameter of the light, degrees (soft shadows widen with it)",
      Range{0.0, 60.0});
    v("rigid_color", rigid_color, "colour of rigid bodies, RGB 0..1");
    v("cloth_color", cloth_color, "colour of cloth, RGB 0..1");
    v("cloth_pattern", cloth_pattern,
      "cloth dye: gingham (bands of cloth_color over white, two particles wide) or plain");
    v("cloth_sheen", cloth_sheen, "cloth sheen reflectance (fabric's grazing highlight), 0 = none", Range{0.0, 1.0});
    v("fluid_radius_scale", fluid_radius_scale, "fluid sphere size in the SSFR passes, particle radii",
      Range{0.5, 4.0});
    v("fluid_filter", fluid_filter, "fluid depth filter");
    v("filter_iterations", filter_iterations, "depth filter iterations (rows then columns, the next columns then rows)",
      Range{0, 16});
    v("filter_max_taps", filter_max_taps, "depth filter taps per side at most (wider: strided)", Range{1, 128});
    v("filter_size", filter_size, "depth filter half-width, particle radii", Range{0.0, 50.0});
    v("filter_max_px", filter_max_px, "depth filter half-width limit, pixels", Range{1, 128});
    v("filter_depth_sigma", filter_depth_sigma, "bilateral range sigma, particle radii", Range{0.01, 100.0});
    v("fluid_gap_fill", fluid_gap_fill,
      "fluid depth gap fill: empty runs between fluid pixels up to this many particle radii wide become "
      "fluid at their neighbours' depth, if both agree (0 = off; spheres only, not with fluid_anisotropy)",
      Range{0.0, 50.0});
    v("fluid_anisotropy", fluid_anisotropy,
      "fluid particles drawn as ellipsoids shaped by their neighbours (Yu & Turk 2013): a spread layer "
      "becomes one flat sheet (compute splats only)");
    v("fluid_occluders", fluid_occluders,
      "fluid depth splat: the surface particles first, then the others unless already hidden (the same image; "
      "with fluid_anisotropy)");
    v("absorption", absorption, "fluid absorption per channel (Beer-Lambert), 1/m");
    v("ior", ior, "fluid refractive index (Snell's law at the surface)", Range{1.0, 3.0});
    v("fresnel_f0", fresnel_f0, "fluid reflectance at normal incidence", Range{0.0, 1.0});
    v("fluid_roughness", fluid_roughness, "fluid surface roughness (GGX alpha): spread of the light's highlight",
      Range{0.01, 1.0});
    v("light_intensity", light_intensity,
      "light_dir's radiance on a white diffuse surface facing it (1 = white): strength of highlights",
      Range{0.0, 100.0});
    v("ssr_steps", ssr_steps, "fluid reflections traced in screen space: steps along the ray (0 = off)", Range{0, 256});
    v("ssr_distance", ssr_distance, "fluid screen-space reflection: length of the traced ray, metres",
      Range{0.01, 100.0});
    v("fluid_wet", fluid_wet, "the surface under resting fluid is darkened as when wet (Lekner & Dorf 1988)");
    v("cube_size", cube_size, "reflection cube map face size, pixels", Range{16, 4096});
    v("fluid_splat", fluid_splat, "fluid passes: compute shaders (GL 4.3: splats, screen passes) or raster sprites");
    v("thickness_downsample", thickness_downsample, "fluid thickness at 1/this resolution (1, 2 or 4)", Range{1, 4});
    v("depth_prepass", depth_prepass, "early depth test of fluid sprites against the scene");
    v("max_point_size", max_point_size, "largest particle sprite, pixels", Range{4.0, 2048.0});
    v("cuda_interop", cuda_interop, "on CUDA, copy particles into OpenGL device to device");
  }
};

}  // namespace seamless
