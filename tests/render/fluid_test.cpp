// Screen-space fluid rendering: fluid pixels exactly where the fluid projects, none elsewhere, and
// the stage images of the dissertation's Figure 4.5.
#include <algorithm>
#include <cmath>
#include <filesystem>

#include "core/phase.hpp"
#include "io/png_io.hpp"
#include "render/headless_output.hpp"
#include "render_test_util.hpp"

namespace seamless::test {
namespace {

struct FluidBlock {
  std::vector<vec3> x;
  std::vector<std::uint32_t> ph;
  float r = 0.02f;
  // 8 x 8 x 8 particles on a lattice of one diameter, centred at (0, 0, 2) in front of the camera.
  FluidBlock() {
    for (int k = 0; k < 8; ++k)
      for (int j = 0; j < 8; ++j)
        for (int i = 0; i < 8; ++i) x.push_back(vec3{(i - 3.5f) * 2 * r, (j - 3.5f) * 2 * r, 2.f + (k - 3.5f) * 2 * r});
    ph.assign(x.size(), phase::kFluid);
  }
  DrawList list() const {
    DrawList d;
    d.positions = x, d.phases = ph, d.particle_radius = r;
    return d;
  }
};

RenderParams fluid_params() {
  RenderParams p;
  p.background = {230 / 255.f, 230 / 255.f, 230 / 255.f};
  return p;
}

// The union of the spheres' projections is inside the box of the particles' projected centres
// grown by the largest projected radius f r / (z - r) (r: the enlarged radius of the SSFR passes) (a sphere's
// silhouette lies within its bounding square in the image). Pixels two beyond that box must be untouched background:
// the depth filter and the shading never write where no sphere was. Pixels inside the projection of the block's front
// face shrunk by a radius are covered by spheres and must differ from the background: thickness > 0 there attenuates
// the refracted background (Beer-Lambert with strongly tinted water, red coefficient 25/m, over at least one
// diameter: at least 1 - exp(-0.5) = 39 % of 230; the default absorption is nearly clear at this size).
TEST(RenderFluid, FluidPixelsExactlyWhereTheFluidProjects) {
  SEAMLESS_REQUIRE_EGL();
  const Intrinsics K = intrinsics(150.f, 79.5f, 59.5f, 160, 120);
  FluidBlock b;
  RenderParams p = fluid_params();
  p.absorption = {25.f, 8.f, 3.5f};
  Renderer r(p, K.width, K.height);
  Pixels img(r.render(b.list(), camera(K)));
  Pixels empty(r.render(DrawList{}, camera(K)));
  float lo_u = 1e9f, hi_u = -1e9f, lo_v = 1e9f, hi_v = -1e9f, rad = 0.f;
  for (vec3 c : b.x) {
    const vec2 q = K.project(c);
    lo_u = std::min(lo_u, q.x), hi_u = std::max(hi_u, q.x), lo_v = std::min(lo_v, q.y), hi_v = std::max(hi_v, q.y);
    const float rs = b.r * RenderParams{}.fluid_radius_scale;  // spheres as the fluid passes draw them
    rad = std::max(rad, K.fx * rs / (c.z - rs));
  }
  // Front face (z = 2 - 3.5 d) spans x, y in +-3.5 d: its projection shrunk by one projected radius.
  const float zf = 2.f - 3.5f * 2 * b.r, half = 3.5f * 2 * b.r;
  const float in_u0 = K.fx * -half / zf + K.cx + rad, in_u1 = K.fx * half / zf + K.cx - rad;
  const float in_v0 = K.fy * -half / zf + K.cy + rad, in_v1 = K.fy * half / zf + K.cy - rad;
  int fluid = 0, outside = 0;
  for (int v = 0; v < img.h; ++v)
    for (int u = 0; u < img.w; ++u) {
      if (u < lo_u - rad - 2 || u > hi_u + rad + 2 || v < lo_v - rad - 2 || v > hi_v + rad + 2) {
        EXPECT_TRUE(same(img.at(u, v), empty.at(u, v))) << "fluid outside its projection at " << u << "," << v;
        ++outside;
      }
      if (u > in_u0 && u < in_u1 && v > in_v0 && v < in_v1) {
        EXPECT_GT(max_diff(img.at(u, v), empty.at(u, v)), 40) << "no fluid at " << u << "," << v;
        ++fluid;
      }
    }
  EXPECT_GT(fluid, 100);
  EXPECT_GT(outside, 5000);
}

// Fluid behind a scene wall is hidden (its depth pass tests against the scene depth).
TEST(RenderFluid, SceneOccludesFluid) {
  SEAMLESS_REQUIRE_EGL();
  const Intrinsics K = intrinsics(150.f, 79.5f, 59.5f, 160, 120);
  FluidBlock b;
  Renderer r(fluid_params(), K.width, K.height);
  r.set_scene_mesh(rectangle(-2.f, 2.f, -2.f, 2.f, 1.f, uchar3{90, 60, 30}));  // a wall at 1 m
  Pixels img(r.render(b.list(), camera(K)));
  for (int v = 0; v < img.h; ++v)
    for (int u = 0; u < img.w; ++u) ASSERT_TRUE(same(img.at(u, v), uchar3{90, 60, 30})) << u << "," << v;
}

// Each stage image is written and shows something (not all black) where the fluid is.
TEST(RenderFluid, StageImagesAreWrittenAndNotEmpty) {
  SEAMLESS_REQUIRE_EGL();
  const Intrinsics K = intrinsics(150.f, 79.5f, 59.5f, 160, 120);
  FluidBlock b;
  RenderParams p = fluid_params();
  p.stage_images = true;
  p.write_frames = true;
  Renderer r(p, K.width, K.height);
  r.set_scene_mesh(rectangle(-3.f, 3.f, -3.f, 3.f, 3.f, uchar3{90, 120, 60}));
  r.draw(b.list(), camera(K));
  const std::string dir = ::testing::TempDir() + "/seamless_render_stages";
  std::filesystem::remove_all(dir);
  HeadlessOutput out(dir, p);
  out.add(r);
  const std::vector<std::string> names = {"1_depth",      "2_depth_filtered", "3_normals",  "4_thickness",
                                          "5_reflection", "6_refraction",     "7_composite"};
  ASSERT_EQ(r.stage_images().size(), names.size());
  for (std::size_t i = 0; i < names.size(); ++i) {
    EXPECT_EQ(r.stage_images()[i].name, names[i]);
    const std::string path = dir + "/stages/000000_" + names[i] + ".png";
    ASSERT_TRUE(std::filesystem::exists(path)) << path;
    Pixels im(read_png_rgb(path));
    const auto lit = std::count_if(im.px.begin(), im.px.end(), [](uchar3 c) { return c.x + c.y + c.z > 30; });
    EXPECT_GT(lit, 100) << names[i] << " is (nearly) black";
  }
  EXPECT_TRUE(std::filesystem::exists(dir + "/frames/000000.png"));
}

}  // namespace
}  // namespace seamless::test
