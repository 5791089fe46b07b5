// Input section of an experiment (`input:` in the YAML): where RGB-D frames come from.
// Owned by the input layer; described by visit() (see core/params.hpp), loaded by src/config.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "core/math.hpp"
#include "core/params.hpp"

namespace seamless {

enum class InputSource { synthetic, tum, frames, kinect, fakenect };
inline std::span<const EnumName<InputSource>> enum_names(InputSource) {
  static constexpr EnumName<InputSource> names[] = {{InputSource::synthetic, "synthetic"},
                                                    {InputSource::tum, "tum"},
                                                    {InputSource::frames, "frames"},
                                                    {InputSource::kinect, "kinect"},
                                                    {InputSource::fakenect, "fakenect"}};
  return names;
}
// How a Kinect v1 delivers depth: raw 11-bit disparity turned into registered metres by seamless
// (kernels/io/kinect_depth.hpp), or libfreenect's own registered millimetres.
enum class KinectDepthMode { raw, registered };
inline std::span<const EnumName<KinectDepthMode>> enum_names(KinectDepthMode) {
  static constexpr EnumName<KinectDepthMode> names[] = {{KinectDepthMode::raw, "raw"},
                                                        {KinectDepthMode::registered, "registered"}};
  return names;
}
enum class MoverKind { person, ball };
inline std::span<const EnumName<MoverKind>> enum_names(MoverKind) {
  static constexpr EnumName<MoverKind> names[] = {{MoverKind::person, "person"}, {MoverKind::ball, "ball"}};
  return names;
}
enum class CameraPath { orbit, still };
inline std::span<const EnumName<CameraPath>> enum_names(CameraPath) {
  static constexpr EnumName<CameraPath> names[] = {{CameraPath::orbit, "orbit"}, {CameraPath::still, "still"}};
  return names;
}
// `auto` is a C++ keyword: the value is `automatic`, its name `auto`.
enum class Association { automatic, file };
inline std::span<const EnumName<Association>> enum_names(Association) {
  static constexpr EnumName<Association> names[] = {{Association::automatic, "auto"}, {Association::file, "file"}};
  return names;
}

// Camera intrinsics: a named preset, `custom` with fx fy cx cy given here, or a camera file.
struct IntrinsicsParams {
  std::string preset = "auto";
  std::string file;                                        // a camera file (io/camera_file.hpp); wins over preset auto
  float fx = 525.f, fy = 525.f, cx = 319.5f, cy = 239.5f;  // used when preset is custom
  int width = 640, height = 480;

  template <class V> void visit(V& v) {
    // TUM values from vision.in.tum.de/data/datasets/rgbd-dataset/file_formats; kinect_v1 is the
    // generic 525/319.5/239.5 set the TUM page gives for the default OpenNI calibration.
    // auto: a folder's calibration.txt (written by `seamless record`), else its 3x3 K file
    // (camera-intrinsics.txt or intrinsics.K.txt, frame folders), else the freiburg preset its name
    // contains (or bonn: the Bonn RGB-D Dynamic dataset's Asus Xtion), else kinect_v1 (also for the
    // synthetic room and a live Kinect).
    v("preset", preset, "intrinsics preset (fx fy cx cy below are used only for custom)",
      Choices{"auto", "freiburg1", "freiburg2", "freiburg3", "kinect_v1", "bonn", "custom"});
    v("file", file,
      "camera file: ORB-SLAM/OpenCV YAML, ROS camera_info YAML or Open3D JSON (told by content); with preset auto");
    // Negative focal lengths (ICL-NUIM's fy = -480) are taken as a flipped image axis.
    v("fx", fx, "focal length x, pixels (custom only; negative: the image's x axis is flipped)", Range{-1e5, 1e5});
    v("fy", fy, "focal length y, pixels (custom only; negative: the image's y axis is flipped)", Range{-1e5, 1e5});
    v("cx", cx, "principal point x, pixels (custom only)", Range{-1e4, 1e4});
    v("cy", cy, "principal point y, pixels (custom only)", Range{-1e4, 1e4});
    v("width", width, "image width, pixels", Range{1, 16384});
    v("height", height, "image height, pixels", Range{1, 16384});
  }
};

// Kinect v1 sensor model of the synthetic room (kernels/io/render_room.hpp, docs/INPUT.md).
struct SyntheticNoiseParams {
  float sigma_disparity = 0.05f;  // pixels, Gaussian disparity noise on top of 1/8-pixel quantisation
  float min_depth = 0.4f;
  float max_depth = 4.0f;
  float max_incidence_deg = 78.f;
  float edge_jump = 0.05f;
  bool projector_shadow = true;

  template <class V> void visit(V& v) {
    v("sigma_disparity", sigma_disparity, "Gaussian disparity noise, pixels (Khoshelham & Elberink 2012)",
      Range{0.0, 5.0});
    v("min_depth", min_depth, "nearest measurable depth, metres", Range{0.0, 100.0});
    v("max_depth", max_depth, "farthest measurable depth, metres", Range{0.0, 100.0});
    v("max_incidence_deg", max_incidence_deg, "no depth beyond this angle between ray and surface normal, degrees",
      Range{0.0, 90.0});
    v("edge_jump", edge_jump, "relative depth jump to a neighbour that drops a pixel as an edge", Range{0.0, 10.0});
    v("projector_shadow", projector_shadow, "drop pixels the IR projector (7.5 cm to the side) cannot see");
  }
};

// Something that moves through the synthetic room (test material of dynamic scenes): a person walking or
// a ball rolling along a path on the floor, at constant speed, present from `start` until the
// path's end (then gone, as if it left the room). Posed per frame by src/io/movers.cpp.
struct MoverParams {
  MoverKind kind = MoverKind::person;
  std::vector<vec3> path;  // waypoints on the floor, room frame (x, y; z is ignored)
  float speed = 1.0f;      // metres per second along the path
  double start = 0.0;      // seconds: when it stands at the path's first point
  float height = 1.75f;    // person: standing height, metres
  float radius = 0.12f;    // ball: radius, metres

  template <class V> void visit(V& v) {
    v("kind", kind, "person (torso, head, arms and legs swinging as it walks) or ball (rolling)");
    v("path", path, "waypoints on the floor in the room frame of groundtruth.txt (x, y, z ignored), metres");
    v("speed", speed, "speed along the path, m/s", Range{0.01, 10.0});
    v("start", start, "time it appears at the path's first point, seconds (it leaves at the path's end)",
      Range{0.0, 1e6});
    v("height", height, "person: standing height, metres", Range{0.5, 2.5});
    v("radius", radius, "ball: radius, metres", Range{0.01, 1.0});
  }
};

// The built-in synthetic room (no data needed; ground-truth poses known exactly).
struct SyntheticParams {
  std::uint64_t seed = 1;
  bool noise = true;
  int frames = 120;
  CameraPath trajectory = CameraPath::orbit;
  double fps = 30.0;
  float radius = 1.6f;      // orbit: horizontal distance to the desk centre, metres
  float height = 1.35f;     // camera height above the floor, metres
  float speed_deg = 15.f;   // orbit: degrees per second around the desk
  float start_deg = -90.f;  // orbit: start angle (-90: in front of the desk, behind the chair)
  float shake = 1.f;        // scale of the hand-held wobble (0 = a perfectly smooth path)
  SyntheticNoiseParams sensor;
  std::vector<MoverParams> movers;  // people and balls moving through the room (ground-truth masks)

  template <class V> void visit(V& v) {
    v("seed", seed, "random seed for the noise and the hand-held wobble");
    v("noise", noise, "add Kinect-like depth noise and dropouts (off: exact depth everywhere)");
    v("frames", frames, "number of frames to generate", Range{1, 1000000});
    v("trajectory", trajectory, "camera path: orbit around the desk, or still (fixed pose)");
    v("fps", fps, "frames per second (timestamps and motion speed)", Range{1.0, 1000.0});
    v("radius", radius, "orbit radius around the desk centre, metres", Range{0.5, 1.8});
    v("height", height, "camera height above the floor, metres (above the furniture)", Range{1.05, 2.3});
    v("speed_deg", speed_deg, "orbit speed, degrees per second", Range{-360.0, 360.0});
    v("start_deg", start_deg, "orbit start angle, degrees", Range{-360.0, 360.0});
    v("shake", shake, "hand-held wobble scale (0 = smooth)", Range{0.0, 5.0});
    v("sensor", sensor, "Kinect v1 sensor model used when noise is on");
    v("movers", movers,
      "people and balls that move through the room; `seamless record` writes their masks "
      "(mask/) and capsules (movers.txt)");
  }
};

// A Kinect v1 through libfreenect (source: kinect) and its recordings (source: fakenect).
struct KinectParams {
  int device_index = 0;
  int queue_size = 4;
  double timeout_s = 5.0;
  KinectDepthMode depth_mode = KinectDepthMode::raw;
  std::string calibration;  // a device.json; empty: the device's, the recording's, or the defaults

  template <class V> void visit(V& v) {
    v("device_index", device_index, "which Kinect (libfreenect device index)", Range{0, 16});
    v("queue_size", queue_size, "frames buffered between capture and processing; a full queue drops the oldest",
      Range{1, 1000});
    v("timeout_s", timeout_s, "give up when no frame arrives for this long, seconds", Range{0.1, 3600.0});
    v("depth_mode", depth_mode,
      "raw: 11-bit disparity registered to colour by seamless (the same code as recordings); registered: "
      "libfreenect's registered millimetres (a live Kinect only)");
    v("calibration", calibration,
      "the unit's registration as a device.json (fakenect-record's format); empty: read from the device, the "
      "recording's device.json, else factory-typical defaults");
  }
};

struct InputParams {
  InputSource source = InputSource::synthetic;
  std::string path;               // TUM folder (source: tum) or frame folder (source: frames)
  double depth_scale = 0.0;       // units per metre; 0: the layout's own (TUM 5000, frames 1000)
  bool check_depth_scale = true;  // compare depth_scale with the depth's Kinect quantisation
  double fps = 30.0;              // frame folders: timestamp = frame number / fps
  bool fill_gaps = false;         // close one-pixel gaps of forward-registered depth
  IntrinsicsParams intrinsics;
  std::int64_t max_frames = 0;  // 0 = all
  std::int64_t first_frame = 0;
  bool skip_bad_frames = false;
  bool undistort = true;    // remove lens distortion of presets that have it (freiburg1/2)
  double max_gt_gap = 0.1;  // seconds: no ground truth across larger motion-capture gaps
  // TUM: pair rgb.txt/depth.txt by time (auto) or trust the folder's association file.
  Association association = Association::automatic;
  double association_max_dt = 0.02;  // TUM's associate.py --max_difference, seconds
  double association_offset = 0.0;   // TUM's associate.py --offset: added to depth timestamps, seconds
  SyntheticParams synthetic;
  KinectParams kinect;

  template <class V> void visit(V& v) {
    v("source", source, "frame source");
    v("path", path,
      "dataset folder: a TUM folder (source: tum), e.g. rgbd_dataset_freiburg1_desk, or a frame folder of "
      "frame-NNNNNN.color/depth/pose files (source: frames), or a fakenect-record folder with INDEX.txt "
      "(source: fakenect; also chosen for any source whose path holds an INDEX.txt)");
    v("depth_scale", depth_scale,
      "depth units per metre in the depth PNGs; 0: the layout's convention (tum 5000, frames 1000 = millimetres)",
      Range{0.0, 1e6});
    v("check_depth_scale", check_depth_scale,
      "stop on a depth_scale that contradicts the depth images' Kinect v1 quantisation steps (docs/INPUT.md); "
      "off for sensors of another geometry");
    v("fps", fps, "frame folders (source: frames): frame rate, timestamp = frame number / fps", Range{0.001, 1e6});
    v("fill_gaps", fill_gaps,
      "tum and frames: fill one-pixel gaps of the depth (left by registering depth to colour by forward projection) "
      "from two opposite neighbours that agree within 3% (kernels/io/fill_gaps.hpp)");
    v("intrinsics", intrinsics, "camera intrinsics");
    v("max_frames", max_frames, "stop after this many frames; 0 = all", Range{0, 1e12});
    v("first_frame", first_frame, "skip frames before this index", Range{0, 1e12});
    v("skip_bad_frames", skip_bad_frames, "skip unreadable frames with a warning instead of stopping");
    v("undistort", undistort, "undistort images whose intrinsics have lens distortion");
    v("max_gt_gap", max_gt_gap, "interpolate ground truth only between samples closer than this, seconds",
      Range{0.0, 10.0});
    // auto follows TUM's convention (rgb.txt and depth.txt are the data; an association file is a
    // derived product and some published ones are partial: fr1_desk's 9-frame sample lists 2 pairs).
    v("association", association,
      "TUM rgb/depth pairing: auto pairs rgb.txt and depth.txt by time like TUM's associate.py (an "
      "associations.txt/associate.txt that disagrees is reported and ignored); file uses that file as written");
    v("association_max_dt", association_max_dt, "auto association: largest rgb/depth timestamp difference, seconds",
      Range{0.0, 1.0});
    v("association_offset", association_offset, "auto association: seconds added to depth timestamps",
      Range{-10.0, 10.0});
    v("synthetic", synthetic, "synthetic room settings (source: synthetic)");
    v("kinect", kinect, "Kinect v1 settings (source: kinect, and fakenect for depth_mode/calibration)");
  }
};

// input.depth_scale as used: an explicit value, else (0) the convention of the source's layout:
// TUM folders store 5000 units per metre, frame folders (7-Scenes, 3DMatch) millimetres.
inline double effective_depth_scale(const InputParams& p) {
  if (p.depth_scale > 0.0) return p.depth_scale;
  return p.source == InputSource::frames ? 1000.0 : 5000.0;
}

}  // namespace seamless
