// The dynamic-pixel kernels (kernels/recon/dynamic.hpp) on one view of the synthetic room with a
// person standing in it: the model is the same view rendered without the person (what a perfect
// map raycast gives), so the truth is the renderer's mover mask. Then the same kernels on CUDA
// against the CPU (Parity: ctest label gpu).
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <memory>
#include <vector>

#include "core/device.hpp"
#include "core/exec.hpp"
#include "io/synthetic_source.hpp"
#include "kernels/recon/dynamic.hpp"
#include "kernels/recon/preprocess.hpp"
#include "recon/volume.hpp"

using namespace seamless;

namespace {

InputParams room(bool person) {
  InputParams in;
  in.source = InputSource::synthetic;
  in.synthetic.frames = 1;
  in.intrinsics.preset = "custom";
  in.intrinsics.fx = in.intrinsics.fy = 262.5f;  // half the Kinect's resolution: fast
  in.intrinsics.cx = 159.5f, in.intrinsics.cy = 119.5f;
  in.intrinsics.width = 320, in.intrinsics.height = 240;
  if (person) {
    MoverParams p;  // standing still (its path's first point) in front of the far wall, behind the desk
    p.kind = MoverKind::person, p.path = {{-0.3f, 1.15f, 0.f}, {1.8f, 1.15f, 0.f}}, p.speed = 0.8f;
    in.synthetic.movers = {p};
  }
  return in;
}

struct Scene {
  Image<float> depth, model_depth;
  Image<std::uint8_t> truth;
  Intrinsics K;
};

Scene render_view() {
  SyntheticSource with(room(true)), without(room(false));
  Scene v;
  RgbdFrame f;
  with.next(f);
  v.K = with.intrinsics();
  v.depth = f.depth.clone(Device::CPU);
  v.truth = f.mover_mask.clone(Device::CPU);
  Image<uchar3> rgb(v.K.width, v.K.height, Device::CPU);
  v.model_depth = Image<float>(v.K.width, v.K.height, Device::CPU);
  without.render(*f.ground_truth, 0, v.model_depth, rgb);
  return v;
}

struct Masks {
  std::vector<std::uint8_t> candidates, mask;
  std::vector<vec3> masked_vertices;
  std::vector<float> masked_depth;
  std::int64_t count = 0;
};

Masks run_on(Device d, const Scene& v) {
  const kernels::DynamicInput defaults{};
  Image<float> depth = v.depth.clone(d), model = v.model_depth.clone(d);
  Image<vec3> mv(v.K.width, v.K.height, d), mn(v.K.width, v.K.height, d), fv(v.K.width, v.K.height, d),
      fn(v.K.width, v.K.height, d);
  Image<std::uint8_t> cand(v.K.width, v.K.height, d), kept(v.K.width, v.K.height, d), mask(v.K.width, v.K.height, d);
  Masks out;
  with_exec(d, [&]<class E>(const E& ex) {
    kernels::Preprocess<E>::depth_to_vertices(ex, model.cview(), v.K, mv.view());
    kernels::Preprocess<E>::vertices_to_normals(ex, mv.cview(), mn.view(), 0.1f);
    kernels::Preprocess<E>::depth_to_vertices(ex, depth.cview(), v.K, fv.view());
    kernels::Preprocess<E>::vertices_to_normals(ex, fv.cview(), fn.view(), 0.1f);
    kernels::DynamicInput in = defaults;
    in.depth = depth.cview();
    in.K = v.K;
    in.model_vertices = mv.cview();
    in.model_normals = mn.cview();
    in.ref_T_cur = SE3::identity();
    kernels::Dynamic<E>::classify_dynamic(ex, in, cand.view());
    kernels::Dynamic<E>::filter_dynamic(ex, cand.cview(), View2D<const std::uint8_t>{}, depth.cview(), 1, 5, 0.05f,
                                        kept.view(), mask.view());
    kernels::Dynamic<E>::mask_vertices(ex, mask.cview(), 1, fv.view(), fn.view());
    kernels::Dynamic<E>::mask_depth(ex, mask.cview(), depth.view());
    out.count = kernels::Dynamic<E>::count_dynamic(ex, mask.cview());
  });
  out.candidates = cand.to_host();
  out.mask = mask.to_host();
  out.masked_vertices = fv.to_host();
  out.masked_depth = depth.to_host();
  return out;
}

double iou(const std::vector<std::uint8_t>& a, const std::vector<std::uint8_t>& b) {
  std::int64_t i = 0, u = 0;
  for (std::size_t k = 0; k < a.size(); ++k) i += a[k] && b[k], u += a[k] || b[k];
  return u ? static_cast<double>(i) / static_cast<double>(u) : 1.0;
}

}  // namespace

// Against a perfect model the only errors are the person's feet (within the residual threshold of
// the floor they stand on: 3 cm of a 1.75 m person) and the silhouette's dilation into depth-
// continuous neighbours, a pixel at the border: together a few per cent of the person's pixels,
// so an IoU of 0.9 leaves margin while a mask missing a limb (~10%) fails.
TEST(DynamicKernels, MaskMatchesTheMoverMaskAgainstAPerfectModel) {
  const Scene v = render_view();
  const Masks m = run_on(Device::CPU, v);
  const std::vector<std::uint8_t> truth = v.truth.to_host();
  std::int64_t person = 0, masked = 0;
  for (std::size_t k = 0; k < truth.size(); ++k) person += truth[k] != 0, masked += m.mask[k] != 0;
  ASSERT_GT(person, 1000) << "the person should fill a good part of the view";
  EXPECT_EQ(m.count, masked);
  EXPECT_GE(iou(m.mask, truth), 0.9);
  // Masked pixels lose their depth and vertices; the others keep them.
  const std::vector<float> depth = v.depth.to_host();
  for (std::size_t k = 0; k < truth.size(); ++k) {
    if (m.mask[k]) {
      EXPECT_EQ(m.masked_depth[k], 0.f);
      EXPECT_EQ(m.masked_vertices[k].z, 0.f);
    } else {
      EXPECT_EQ(m.masked_depth[k], depth[k]);
    }
  }
}

// The same frame compared with itself has nothing dynamic: noise alone makes no mask.
TEST(DynamicKernels, NoDynamicPixelsAgainstItself) {
  Scene v = render_view();
  v.model_depth = v.depth.clone(Device::CPU);
  EXPECT_EQ(run_on(Device::CPU, v).count, 0);
}

// CUDA against the CPU: the masks are decisions on thresholds, so a pixel whose residual sits within
// float rounding (fused multiply-adds on the GPU) of a threshold may differ; at most 0.1% of pixels.
TEST(DynamicKernels, Parity) {
  if (!cuda_available()) GTEST_SKIP() << "no CUDA device";
  const Scene v = render_view();
  const Masks c = run_on(Device::CPU, v), g = run_on(Device::CUDA, v);
  std::int64_t diff = 0;
  for (std::size_t k = 0; k < c.mask.size(); ++k)
    diff += (c.mask[k] != g.mask[k]) + (c.candidates[k] != g.candidates[k]);
  EXPECT_LE(diff, static_cast<std::int64_t>(c.mask.size() / 1000));
  EXPECT_NEAR(static_cast<double>(c.count), static_cast<double>(g.count), c.mask.size() / 1000.0);
}

namespace {

// age_dynamic over a sequence of frames: a 64x48 camera, every pixel a candidate on a wall facing
// it at depth(frame) metres, the camera moved sideways by shift(frame) metres (x, world = the first
// camera's frame). Returns each frame's ages and the candidates left.
struct Aged {
  std::vector<std::vector<std::uint8_t>> age, candidates;
};
template <class Depth, class Shift>
Aged age_sequence(Device d, int frames, int static_after, Depth depth_of, Shift shift_of) {
  Intrinsics K;
  K.fx = K.fy = 52.5f, K.cx = 31.5f, K.cy = 23.5f, K.width = 64, K.height = 48;
  Image<float> depth(K.width, K.height, d), anchor(K.width, K.height, d), prev_anchor(K.width, K.height, d);
  Image<std::uint8_t> cand(K.width, K.height, d), age(K.width, K.height, d), prev_age(K.width, K.height, d);
  prev_anchor.buffer().zero();
  prev_age.buffer().zero();
  Aged out;
  SE3 world_T_prev = SE3::identity();
  for (int f = 0; f < frames; ++f) {
    const SE3 world_T_cur{mat3::identity(), {shift_of(f), 0.f, 0.f}};
    // The wall at z = depth_of(f) in the world: seen from a camera moved along x, at the same depth.
    const std::vector<float> z(K.width * K.height, depth_of(f));
    const std::vector<std::uint8_t> ones(K.width * K.height, 1);
    depth.buffer().copy_from_host(z.data(), depth.buffer().size());
    cand.buffer().copy_from_host(ones.data(), cand.buffer().size());
    kernels::DynamicInput in;
    in.depth = depth.cview();
    in.K = K;
    in.disparity_step_per_baseline = 0.f;  // no quantisation: the threshold is max(3 cm, 3 sigma(z))
    with_exec(d, [&]<class E>(const E& ex) {
      kernels::Dynamic<E>::age_dynamic(ex, in, prev_anchor.cview(), prev_age.cview(),
                                       world_T_prev.inverse() * world_T_cur, static_after, cand.view(), age.view(),
                                       anchor.view());
    });
    prev_age.buffer().copy_from(age.buffer());
    prev_anchor.buffer().copy_from(anchor.buffer());
    world_T_prev = world_T_cur;
    out.age.push_back(age.to_host());
    out.candidates.push_back(cand.to_host());
  }
  return out;
}

int count(const std::vector<std::uint8_t>& v) {
  int n = 0;
  for (std::uint8_t b : v) n += b != 0;
  return n;
}

}  // namespace

// A surface that stays in place ages by one a frame, also seen from a camera that moves (2 cm a
// frame sideways at 2 m, fx 52.5: its points land 0.525 px to the side in the previous frame,
// the nearest pixel one column over), and is cleared once older than static_after. The pixels
// that come into view at the border take the age of their neighbours within search_radius (2)
// at the same depth: the whole wall ages together.
TEST(DynamicKernels, AStillSurfaceAgesAndBecomesStatic) {
  const Aged a = age_sequence(
      Device::CPU, 8, 5, [](int) { return 2.f; }, [](int f) { return 0.02f * f; });
  for (int f = 0; f < 8; ++f) {
    int wrong_age = 0;
    for (std::uint8_t g : a.age[f]) wrong_age += g != f + 1;
    EXPECT_EQ(wrong_age, 0) << "frame " << f;
    // Frame 5 is the first with age 6 > 5.
    EXPECT_EQ(count(a.candidates[f]), f < 5 ? 64 * 48 : 0) << "frame " << f;
  }
}

// A surface moving along the ray by more than the residual threshold each frame (4.5 cm a frame;
// the threshold is 3 cm up to 2.58 m, where 3 sigma = 3 * 0.0015 z^2 passes it) restarts every
// frame; one creeping by 1.2 cm a frame is a threshold from its anchor after at most three frames
// and restarts then: with static_after 4 neither is ever cleared.
TEST(DynamicKernels, AMovingSurfaceNeverBecomesStatic) {
  const Aged fast = age_sequence(
      Device::CPU, 12, 4, [](int f) { return 2.f + 0.045f * f; }, [](int) { return 0.f; });
  const Aged creep = age_sequence(
      Device::CPU, 12, 4, [](int f) { return 2.f + 0.012f * f; }, [](int) { return 0.f; });
  for (int f = 0; f < 12; ++f) {
    EXPECT_EQ(count(fast.candidates[f]), 64 * 48) << "frame " << f;
    EXPECT_EQ(fast.age[f][0], 1) << "frame " << f;
    EXPECT_EQ(count(creep.candidates[f]), 64 * 48) << "frame " << f;
    EXPECT_LE(creep.age[f][0], 3) << "frame " << f;
  }
}

// CUDA against the CPU on the moving camera's sequence: ages are integer decisions on a threshold
// of float depths computed the same way; allow 0.1% of pixels (fused multiply-adds at a threshold).
TEST(DynamicKernels, AgeParity) {
  if (!cuda_available()) GTEST_SKIP() << "no CUDA device";
  auto depth = [](int f) { return 2.f + 0.01f * f; };
  auto shift = [](int f) { return 0.02f * f; };
  const Aged c = age_sequence(Device::CPU, 8, 5, depth, shift), g = age_sequence(Device::CUDA, 8, 5, depth, shift);
  for (int f = 0; f < 8; ++f) {
    int diff = 0;
    for (std::size_t k = 0; k < c.age[f].size(); ++k)
      diff += (c.age[f][k] != g.age[f][k]) + (c.candidates[f][k] != g.candidates[f][k]);
    EXPECT_LE(diff, 4) << "frame " << f;
  }
}

namespace {

// Evidence of free space (DynamicSpace::require_free_space through Volume::require_free_space): a
// wall at world z = 2 m fused three times from the world origin (1 cm voxels, 4 cm truncation, so
// the voxels from 1.96 m to the wall's front hold +4 cm, the wall's own about 0), then a camera
// moved by (0.1, 0, 0.5) m measures four bands of rows, every pixel a candidate: at world z 1.935 m
// (5 cm in front of the wall: rays went through), 2.0 m (on the wall), 1.5 m (half a metre in
// front: in the voxel-hashed volume no block was allocated there) and 2.06 m (behind the wall
// beyond the truncation: never observed). Returns which candidates are left.
constexpr int kBandRows = 12;
const float kBandZ[4] = {1.935f, 2.0f, 1.5f, 2.06f};

std::vector<std::uint8_t> free_space_bands(Device d, const VolumeParams& vp, float min_weight, bool require_seen_free,
                                           bool store_free_space = false) {
  Intrinsics K;
  K.fx = K.fy = 52.5f, K.cx = 31.5f, K.cy = 23.5f, K.width = 64, K.height = 48;
  std::unique_ptr<Volume> volume = make_volume(vp, d);
  volume->set_free_space_storage(store_free_space);
  Image<float> depth(K.width, K.height, d);
  const std::vector<float> wall(K.width * K.height, 2.f);
  depth.buffer().copy_from_host(wall.data(), depth.buffer().size());
  for (int f = 0; f < 3; ++f) volume->integrate(depth, Image<uchar3>(), K, SE3::identity());
  const SE3 moved{mat3::identity(), {0.1f, 0.f, 0.5f}};
  std::vector<float> z(K.width * K.height);
  for (int y = 0; y < K.height; ++y)
    for (int x = 0; x < K.width; ++x) z[y * K.width + x] = kBandZ[y / kBandRows] - moved.t.z;
  depth.buffer().copy_from_host(z.data(), depth.buffer().size());
  std::vector<std::uint8_t> ones(K.width * K.height, 1);
  ones[5] = 0;  // a pixel that is no candidate stays none
  Image<std::uint8_t> cand(K.width, K.height, d);
  cand.buffer().copy_from_host(ones.data(), cand.buffer().size());
  volume->require_free_space(depth, K, moved, min_weight, require_seen_free, cand);
  return cand.to_host();
}

VolumeParams wall_volume() {
  VolumeParams vp;
  vp.voxel_size = 0.01f, vp.truncation = 0.04f;
  vp.hash_buckets = 1 << 14, vp.capacity = 1 << 12;
  return vp;
}

// Candidates left in each band (of 12 x 64 pixels; band 0 has the one pixel that was none).
std::vector<int> band_counts(const std::vector<std::uint8_t>& c) {
  std::vector<int> n(4, 0);
  for (std::size_t k = 0; k < c.size(); ++k) n[k / (64 * kBandRows)] += c[k] != 0;
  return n;
}

}  // namespace

// Only the space the earlier frames saw through counts as evidence of motion: the band in front of
// the wall within its blocks stays a candidate; on the wall it is occupied, half a metre in front
// the hashed volume stores nothing (unknown: a chair's seat seen for the first time, but also a
// person walking through the room's middle), behind the wall is unobserved. The bands are whole
// voxels away from the thresholds (a cell of +4 cm voxels against half the truncation, 2 cm), so
// the counts are exact.
TEST(DynamicKernels, FreeSpaceEvidenceFromTheVolume) {
  const int band = 64 * kBandRows;
  EXPECT_EQ(band_counts(free_space_bands(Device::CPU, wall_volume(), 2.f, true)),
            (std::vector<int>{band - 1, 0, 0, 0}));
  // not_occupied: only the surface the volume holds is cleared.
  EXPECT_EQ(band_counts(free_space_bands(Device::CPU, wall_volume(), 2.f, false)),
            (std::vector<int>{band - 1, 0, band, band}));
  // Three frames fused: a minimum weight of 4 leaves nothing observed.
  EXPECT_EQ(band_counts(free_space_bands(Device::CPU, wall_volume(), 4.f, true)), (std::vector<int>{0, 0, 0, 0}));
  EXPECT_EQ(band_counts(free_space_bands(Device::CPU, wall_volume(), 4.f, false)),
            (std::vector<int>{band - 1, band, band, band}));
  // The dense grid stores every voxel of its cube, so it knows the space half a metre in front of
  // the wall was seen through (2 cm voxels: 128^3 of them cover the scene; 1.935 and 1.5 m are still
  // a whole voxel and more beyond the truncation in front of the wall).
  VolumeParams dense = wall_volume();
  dense.layout = VolumeLayout::dense, dense.voxel_size = 0.02f, dense.dense_resolution = 128;
  EXPECT_EQ(band_counts(free_space_bands(Device::CPU, dense, 2.f, true)), (std::vector<int>{band - 1, 0, band, 0}));
}

// With the free space stored (what seen_free turns on in a run: TrackingSession), the voxel-hashed
// volume knows the space half a metre in front of the wall as the dense grid does: the rays of the
// three frames passed it (1.5 m is 46 cm in front of the band), and it is seen free at weight 3;
// the other bands are as before (not_occupied: only the wall's band is cleared).
TEST(DynamicKernels, FreeSpaceEvidenceFromTheStoredFreeSpace) {
  const int band = 64 * kBandRows;
  EXPECT_EQ(band_counts(free_space_bands(Device::CPU, wall_volume(), 2.f, true, true)),
            (std::vector<int>{band - 1, 0, band, 0}));
  EXPECT_EQ(band_counts(free_space_bands(Device::CPU, wall_volume(), 2.f, false, true)),
            (std::vector<int>{band - 1, 0, band, band}));
}

// CUDA against the CPU: the same lookups and the same float sums decide at whole voxels from the
// threshold, so the results are equal.
TEST(DynamicKernels, FreeSpaceParity) {
  if (!cuda_available()) GTEST_SKIP() << "no CUDA device";
  for (bool store : {false, true})
    for (bool require : {true, false})
      EXPECT_EQ(free_space_bands(Device::CPU, wall_volume(), 2.f, require, store),
                free_space_bands(Device::CUDA, wall_volume(), 2.f, require, store));
}

namespace {

// Evidence from past views (Dynamic::views_evidence, free_space_evidence views): one past view, a
// 64x48 camera at the world origin that saw a wall at z = 2 m, but for an object at 1 m on the
// pixel (20, 6) and no reading on row 40. The current camera is the same one, so each point
// projects to its own pixel (the view is kept at full resolution here). Four bands of rows, now
// measured at 1.5 m (in front of the wall: every ray of the 3x3 window passed through it), 2.0 m
// (on the wall: seen at), 2.5 m (behind the wall: hidden) and 1.5 m over the row without a reading
// (no evidence). The left half of the columns are model candidates (1), the right half undecided
// (2: no model near). With `prev_value` 1, the previous frame kept (1) every pixel at the current
// depth, so every pixel continues it; with 2 it kept them for its frame only (views_evidence's 2),
// which nothing continues; with 0 there is no previous frame.
std::vector<std::uint8_t> views_bands(Device d, std::uint8_t prev_value) {
  Intrinsics K;
  K.fx = K.fy = 52.5f, K.cx = 31.5f, K.cy = 23.5f, K.width = 64, K.height = 48;
  const int n = K.width * K.height;
  std::vector<float> past(n, 2.f), now(n);
  past[6 * K.width + 20] = 1.f;
  for (int x = 0; x < K.width; ++x) past[40 * K.width + x] = 0.f;
  const float band_z[4] = {1.5f, 2.f, 2.5f, 1.5f};
  std::vector<std::uint8_t> cand(n);
  for (int y = 0; y < K.height; ++y)
    for (int x = 0; x < K.width; ++x)
      now[y * K.width + x] = band_z[y / kBandRows], cand[y * K.width + x] = x < K.width / 2 ? 1 : 2;
  Image<float> past_depth(K.width, K.height, d), depth(K.width, K.height, d), prev_depth(K.width, K.height, d);
  Image<std::uint8_t> c(K.width, K.height, d), prev_kept(K.width, K.height, d);
  past_depth.buffer().copy_from_host(past.data(), past_depth.buffer().size());
  depth.buffer().copy_from_host(now.data(), depth.buffer().size());
  prev_depth.buffer().copy_from_host(now.data(), prev_depth.buffer().size());
  c.buffer().copy_from_host(cand.data(), c.buffer().size());
  const std::vector<std::uint8_t> kept(n, prev_value);
  prev_kept.buffer().copy_from_host(kept.data(), prev_kept.buffer().size());
  kernels::DynamicInput in;
  in.depth = depth.cview();
  in.K = K;
  kernels::PastViews views;
  views.K = K;
  views.depth[0] = past_depth.cview();
  views.view_T_world[0] = SE3::identity();
  views.count = 1;
  with_exec(d, [&]<class E>(const E& ex) {
    kernels::Dynamic<E>::views_evidence(ex, in, SE3::identity(), views,
                                        prev_value ? prev_kept.cview() : View2D<const std::uint8_t>{},
                                        prev_depth.cview(), SE3::identity(), c.view());
  });
  return c.to_host();
}

// Pixels of one band and half (left: model candidates, right: undecided) with each value, leaving
// out the image's border (a window there reaches out of the view: no evidence).
int band_half_count(const std::vector<std::uint8_t>& c, int band, bool right, std::uint8_t value) {
  int k = 0;
  for (int y = std::max(band * kBandRows, 1); y < std::min((band + 1) * kBandRows, 47); ++y)
    for (int x = right ? 32 : 1; x < (right ? 63 : 32); ++x) k += c[y * 64 + x] == value;
  return k;
}

// The pixels band_half_count looks at in a band's half.
int inner(int band) { return (band == 0 || band == 3 ? kBandRows - 1 : kBandRows) * 31; }

}  // namespace

// Seen through: a candidate, undecided or not, but for the 3x3 pixels around the object at 1 m
// (their windows hold its reading, nearer than 1.5 m: at a silhouette nothing is seen through; the
// pixel itself is hidden behind it). Seen at (the wall): static. Hidden, or no reading in the view:
// no evidence, so a model candidate stays one for this frame only (2) and an undecided pixel is
// static. With every pixel continued from the previous frame, every model candidate not seen
// through is one (1) and every undecided one is masked for this frame only (2: it has no model
// test of its own to carry a mover on). A previous frame that kept its pixels for its frame only
// continues nothing. The depths lie 0.5 m from the wall and the threshold is 3 cm to 2.58 m, so
// the counts are exact.
TEST(DynamicKernels, EvidenceFromPastViews) {
  const std::vector<std::uint8_t> c = views_bands(Device::CPU, 0);
  // Band 0: the object's pixel (20, 6) and its 8 neighbours are left of the middle.
  EXPECT_EQ(band_half_count(c, 0, false, 1), inner(0) - 9);
  EXPECT_EQ(band_half_count(c, 0, false, 2), 9);
  EXPECT_EQ(band_half_count(c, 0, true, 1), inner(0));
  EXPECT_EQ(band_half_count(c, 1, false, 0), inner(1));
  EXPECT_EQ(band_half_count(c, 1, true, 0), inner(1));
  EXPECT_EQ(band_half_count(c, 2, false, 2), inner(2));
  EXPECT_EQ(band_half_count(c, 2, true, 0), inner(2));
  // Band 3: rows 39-41 have the row without a reading in their window (31 pixels a row and half);
  // the rest of the band is seen through.
  EXPECT_EQ(band_half_count(c, 3, false, 2), 31 * 3);
  EXPECT_EQ(band_half_count(c, 3, false, 1), inner(3) - 31 * 3);
  EXPECT_EQ(band_half_count(c, 3, true, 0), 31 * 3);
  EXPECT_EQ(band_half_count(c, 3, true, 1), inner(3) - 31 * 3);
  const std::vector<std::uint8_t> cont = views_bands(Device::CPU, 1);
  for (int band = 0; band < 4; ++band) EXPECT_EQ(band_half_count(cont, band, false, 1), inner(band)) << "band " << band;
  EXPECT_EQ(band_half_count(cont, 0, true, 1), inner(0));
  EXPECT_EQ(band_half_count(cont, 1, true, 2), inner(1));
  EXPECT_EQ(band_half_count(cont, 2, true, 2), inner(2));
  EXPECT_EQ(band_half_count(cont, 3, true, 2), 31 * 3);
  EXPECT_EQ(band_half_count(cont, 3, true, 1), inner(3) - 31 * 3);
  EXPECT_EQ(views_bands(Device::CPU, 2), c);
}

// CUDA against the CPU: the same projections decide half a metre from the thresholds: equal.
TEST(DynamicKernels, EvidenceFromPastViewsParity) {
  if (!cuda_available()) GTEST_SKIP() << "no CUDA device";
  for (std::uint8_t prev : {0, 1, 2}) EXPECT_EQ(views_bands(Device::CPU, prev), views_bands(Device::CUDA, prev));
}
