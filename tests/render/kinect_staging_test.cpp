// The Kinect view's images staged on a worker thread (Renderer::stage_kinect_images) draw the
// same pixels as set_kinect_view's own copy: frame after frame (the staging buffer's two halves
// in turn), with images that change size, with a colour region (the fluid's tint is the region's
// mean colour), and a staged copy that is dropped or never used leaves no trace.
#include <algorithm>
#include <vector>

#include "core/phase.hpp"
#include "render_test_util.hpp"

namespace seamless::test::kinect_staging {

constexpr int kW = 160, kH = 120;  // the framebuffer

// A w x h frame whose colours and depths differ with `seed`: a wall at 1.2-1.5 m with a hole
// (no reading) that moves with the seed; white outside the colour region, if one is given.
struct Frame {
  Intrinsics K;
  Image<uchar3> rgb;
  Image<float> depth;
  PixelRect region;
  Frame(int w, int h, int seed, PixelRect colour_region = {})
      : K(intrinsics(0.75f * w, 0.5f * w, 0.5f * h, w, h)), region(colour_region) {
    std::vector<uchar3> c(static_cast<std::size_t>(w) * h);
    std::vector<float> d(c.size());
    for (int v = 0; v < h; ++v)
      for (int u = 0; u < w; ++u) {
        const std::size_t i = static_cast<std::size_t>(v) * w + u;
        c[i] = {static_cast<std::uint8_t>(u * 3 + seed * 40), static_cast<std::uint8_t>(v * 2 + seed * 17),
                static_cast<std::uint8_t>((u + v) * seed)};
        // Outside the colour region, white (a mean over the whole image would differ clearly).
        if (!region.empty() &&
            (u < region.x || v < region.y || u >= region.x + region.width || v >= region.y + region.height))
          c[i] = {255, 255, 255};
        const bool hole = u / 16 == seed % (w / 16) && v < h / 2;
        d[i] = hole ? 0.f : 1.2f + 0.3f * static_cast<float>(u) / static_cast<float>(w);
      }
    rgb = Image<uchar3>::from_host(c, w, h, Device::CPU);
    depth = Image<float>::from_host(d, w, h, Device::CPU);
  }
  uchar3 rgb_at(int u, int v) const { return rgb.to_host()[static_cast<std::size_t>(v) * K.width + u]; }
};

// A fluid block 1 m in front of the camera over the image's centre: screen-space fluid, which
// reflects the image's mean colour (without screen-space reflections).
struct Fluid {
  std::vector<vec3> x;
  std::vector<std::uint32_t> ph;
  Fluid() {
    for (int i = 0; i < 6; ++i)
      for (int j = 0; j < 6; ++j)
        for (int k = 0; k < 3; ++k) x.push_back({-0.05f + 0.02f * i, -0.05f + 0.02f * j, 1.0f + 0.02f * k});
    ph.assign(x.size(), phase::kFluid);
  }
  DrawList list() const {
    DrawList l;
    l.positions = x, l.phases = ph, l.particle_radius = 0.012f;
    return l;
  }
};

RenderParams kinect_params() {
  RenderParams p;
  p.view = RenderView::kinect;
  p.fluid = FluidDraw::ssfr;
  p.ssr_steps = 0;  // the fluid reflects the image's mean colour (set with the images)
  return p;
}

std::vector<uchar3> draw(Renderer& r, const Frame& f, const Fluid& fluid) {
  r.set_kinect_view(f.rgb, f.depth, f.K, SE3::identity(), f.region);
  return r.render(fluid.list(), RenderCamera{}).to_host();
}

bool equal(const std::vector<uchar3>& a, const std::vector<uchar3>& b) {
  return std::equal(a.begin(), a.end(), b.begin(), b.end(), same);
}

TEST(RenderKinectStaging, StagedFramesDrawTheSamePixels) {
  SEAMLESS_REQUIRE_EGL();
  const Fluid fluid;
  // Three frames of the framebuffer's size (halves 0, 1, 0: the first half is written again after
  // its fence), one larger (the buffer grows), one smaller with a colour region, one as the first.
  std::vector<Frame> frames;
  for (int s = 1; s <= 3; ++s) frames.emplace_back(kW, kH, s);
  frames.emplace_back(200, 150, 4);
  frames.emplace_back(120, 90, 5, PixelRect{8, 6, 100, 75});
  frames.emplace_back(kW, kH, 6);
  Renderer direct(kinect_params(), kW, kH), staged(kinect_params(), kW, kH);
  std::vector<uchar3> last;
  for (std::size_t i = 0; i < frames.size(); ++i) {
    const Frame& f = frames[i];
    const std::vector<uchar3> want = draw(direct, f, fluid);
    ASSERT_TRUE(staged.stage_kinect_images(f.rgb, f.depth, f.region)) << "frame " << i << " was not staged";
    const std::vector<uchar3> got = draw(staged, f, fluid);
    ASSERT_EQ(got.size(), want.size());
    std::size_t differ = 0;
    for (std::size_t k = 0; k < want.size(); ++k) differ += !same(got[k], want[k]);
    EXPECT_EQ(differ, 0u) << "frame " << i << ": pixels differ from set_kinect_view's own copy";
    // The frames differ from each other (so a stale half would show); where the image is drawn
    // 1:1 the corners (no fluid) are this frame's image and the centre is fluid.
    EXPECT_FALSE(equal(want, last)) << "frame " << i;
    last = want;
    if (f.K.width == kW && f.region.empty()) {
      EXPECT_TRUE(same(want[0], f.rgb_at(0, 0))) << "frame " << i;
      EXPECT_TRUE(same(want[want.size() - 1], f.rgb_at(kW - 1, kH - 1))) << "frame " << i;
      EXPECT_FALSE(same(want[static_cast<std::size_t>(kH / 2) * kW + kW / 2], f.rgb_at(kW / 2, kH / 2)))
          << "frame " << i << ": no fluid drawn";
    }
  }
}

// Other images than those staged, or the staged ones changed after a drop: set_kinect_view
// copies what it is given.
TEST(RenderKinectStaging, OtherOrChangedImagesAreCopiedAsGiven) {
  SEAMLESS_REQUIRE_EGL();
  const Fluid fluid;
  Frame a(kW, kH, 1), b(kW, kH, 2);
  Renderer direct(kinect_params(), kW, kH), staged(kinect_params(), kW, kH);
  ASSERT_TRUE(staged.stage_kinect_images(a.rgb, a.depth));
  EXPECT_TRUE(equal(draw(staged, b, fluid), draw(direct, b, fluid))) << "staged a, set b";

  ASSERT_TRUE(staged.stage_kinect_images(a.rgb, a.depth));
  staged.drop_staged_kinect_images();
  // a refilled in place (as a frame source does): same memory, new pixels.
  Frame c(kW, kH, 3);
  a.rgb.buffer().copy_from(c.rgb.buffer());
  a.depth.buffer().copy_from(c.depth.buffer());
  EXPECT_TRUE(equal(draw(staged, a, fluid), draw(direct, c, fluid))) << "dropped a, a refilled";
}

// A staged copy never used: the renderer waits for it when it goes.
TEST(RenderKinectStaging, StagedCopyNeverUsed) {
  SEAMLESS_REQUIRE_EGL();
  Frame a(640, 480, 1);
  for (int i = 0; i < 3; ++i) {
    Renderer r(kinect_params(), kW, kH);
    EXPECT_TRUE(r.stage_kinect_images(a.rgb, a.depth));
    if (i == 1) {
      EXPECT_TRUE(r.stage_kinect_images(a.rgb, a.depth));  // staged twice: the first is dropped
    }
    if (i == 2) r.drop_staged_kinect_images();
  }
}

}  // namespace seamless::test::kinect_staging
