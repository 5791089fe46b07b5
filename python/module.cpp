// seamless._seamless: the compiled half of the Python module (python/seamless/__init__.py is the
// other). It runs the subcommands' own functions (app/api.hpp) on a RunContext, as the CLI does,
// and hands the results over as NumPy arrays that own the C++ vectors they view (no copy).
// See docs/PYTHON.md.
#include <pybind11/functional.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <csignal>
#include <cstring>
#include <map>

#include "app/api.hpp"
#include "config/config.hpp"
#include "core/error.hpp"
#include "core/interrupt.hpp"
#include "core/log.hpp"
#include "core/progress.hpp"
#include "io/callback_source.hpp"
#include "io/intrinsics_presets.hpp"
#include "seamless/build_config.hpp"
#include "seamless/git_commit.hpp"

namespace py = pybind11;
using namespace seamless;

namespace {

// --- arrays that own their C++ storage ---------------------------------------------------------

// A NumPy array over `v`'s memory, which the array keeps alive (a capsule owns the moved vector).
template <class Elem, class T> py::array owned(std::vector<T>&& v, std::vector<py::ssize_t> shape) {
  auto* held = new std::vector<T>(std::move(v));
  py::capsule owner(held, [](void* p) { delete static_cast<std::vector<T>*>(p); });
  return py::array_t<Elem>(shape, reinterpret_cast<const Elem*>(held->data()), owner);
}

py::array owned_vec3(std::vector<vec3>&& v) {
  const auto n = static_cast<py::ssize_t>(v.size());
  return owned<float>(std::move(v), {n, 3});
}

// A host image as an H x W (x C) array owning the image.
template <class Elem, class T> py::array owned_image(Image<T>&& im, py::ssize_t channels) {
  auto* held = new Image<T>(std::move(im));
  py::capsule owner(held, [](void* p) { delete static_cast<Image<T>*>(p); });
  std::vector<py::ssize_t> shape{held->height(), held->width()};
  if (channels > 1) shape.push_back(channels);
  return py::array_t<Elem>(shape, reinterpret_cast<const Elem*>(held->buffer().data()), owner);
}

// --- results ---------------------------------------------------------------------------------

// Camera-to-world 4 x 4 matrices (from the TUM rows' quaternions, in double, as trajectory.txt
// holds them) and the timestamps.
py::dict trajectory_arrays(const Trajectory& tr) {
  const auto n = static_cast<py::ssize_t>(tr.size());
  py::array_t<double> poses({n, py::ssize_t{4}, py::ssize_t{4}}), stamps(n), rows({n, py::ssize_t{8}});
  auto P = poses.mutable_unchecked<3>();
  auto S = stamps.mutable_unchecked<1>();
  auto R = rows.mutable_unchecked<2>();
  for (py::ssize_t i = 0; i < n; ++i) {
    const TumPose& p = tr[static_cast<std::size_t>(i)];
    double x = p.q[0], y = p.q[1], z = p.q[2], w = p.q[3];
    const double s = 1.0 / std::sqrt(x * x + y * y + z * z + w * w);
    x *= s, y *= s, z *= s, w *= s;
    const double m[3][3] = {{1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)},
                            {2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)},
                            {2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)}};
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c) P(i, r, c) = m[r][c];
      P(i, r, 3) = p.t[r];
      P(i, 3, r) = 0.0;
    }
    P(i, 3, 3) = 1.0;
    S(i) = p.timestamp;
    R(i, 0) = p.timestamp;
    for (int k = 0; k < 3; ++k) R(i, 1 + k) = p.t[k];
    for (int k = 0; k < 4; ++k) R(i, 4 + k) = p.q[k];
  }
  py::dict d;
  d["poses"] = poses, d["timestamps"] = stamps, d["tum"] = rows;
  return d;
}

py::dict frame_records(const std::vector<FrameRecord>& frames) {
  const auto n = static_cast<py::ssize_t>(frames.size());
  py::array_t<std::int64_t> index(n);
  py::array_t<double> stamp(n), pre(n), track(n), fuse(n), total(n), residual(n), inliers(n);
  py::array_t<bool> ok(n), fused(n);
  py::list status;
  for (py::ssize_t i = 0; i < n; ++i) {
    const FrameRecord& f = frames[static_cast<std::size_t>(i)];
    index.mutable_at(i) = f.frame, stamp.mutable_at(i) = f.timestamp;
    ok.mutable_at(i) = f.result.ok(), fused.mutable_at(i) = f.fused;
    pre.mutable_at(i) = f.preprocess_ms, track.mutable_at(i) = f.track_ms;
    fuse.mutable_at(i) = f.fuse_ms, total.mutable_at(i) = f.frame_ms;
    residual.mutable_at(i) = f.result.residual_rms, inliers.mutable_at(i) = f.result.inlier_ratio;
    status.append(to_string(f.result.status));
  }
  py::dict d;
  d["frame"] = index, d["timestamp"] = stamp, d["tracked"] = ok, d["fused"] = fused, d["status"] = status;
  d["preprocess_ms"] = pre, d["track_ms"] = track, d["fuse_ms"] = fuse, d["frame_ms"] = total;
  d["residual_rms"] = residual, d["inlier_ratio"] = inliers;
  return d;
}

py::dict mesh_arrays(Mesh&& m) {
  py::dict d;
  const auto nf = static_cast<py::ssize_t>(m.triangles.size()), nc = static_cast<py::ssize_t>(m.colors.size());
  d["vertices"] = owned_vec3(std::move(m.positions));
  d["normals"] = owned_vec3(std::move(m.normals));
  d["colours"] = owned<std::uint8_t>(std::move(m.colors), {nc, 3});
  d["faces"] = owned<std::int32_t>(std::move(m.triangles), {nf, 3});
  return d;
}

py::dict particle_arrays(ParticleState&& s) {
  py::dict d;
  const auto n = static_cast<py::ssize_t>(s.x.size());
  d["positions"] = owned_vec3(std::move(s.x));
  d["velocities"] = owned_vec3(std::move(s.v));
  d["inv_mass"] = owned<float>(std::move(s.inv_mass), {n});
  d["phase"] = owned<std::uint32_t>(std::move(s.phase), {n});
  return d;
}

py::dict solver_stats(const SolverStats& s) {
  py::dict d;
  d["particles"] = s.particles, d["fluid_particles"] = s.fluid_particles, d["cloth_particles"] = s.cloth_particles;
  d["rigid_particles"] = s.rigid_particles, d["rigid_bodies"] = s.rigid_bodies;
  d["static_particles"] = s.static_particles, d["substeps"] = s.substeps, d["time"] = s.time, d["steps"] = s.steps;
  d["neighbour_overflow"] = s.neighbour_overflow, d["static_neighbour_overflow"] = s.static_neighbour_overflow;
  d["max_speed"] = s.max_speed;
  return d;
}

// Every stage's rows of the run's timer (timings.csv): frame numbers and milliseconds.
py::dict timing_arrays(const std::vector<StageTimer::Row>& rows) {
  std::map<std::string, std::pair<std::vector<std::int64_t>, std::vector<double>>> by_stage;
  for (const auto& r : rows) {
    auto& [frames, ms] = by_stage[r.stage];
    frames.push_back(r.frame), ms.push_back(r.ms);
  }
  py::dict d;
  for (auto& [stage, fm] : by_stage) {
    const auto n = static_cast<py::ssize_t>(fm.first.size());
    py::dict s;
    s["frame"] = owned<std::int64_t>(std::move(fm.first), {n});
    s["ms"] = owned<double>(std::move(fm.second), {n});
    d[py::str(stage)] = s;
  }
  return d;
}

py::dict scan_arrays(app::ScanResult&& r) {
  py::dict d = trajectory_arrays(r.tracking.trajectory);
  d["frames"] = frame_records(r.tracking.frames);
  d["lost_frames"] = r.tracking.lost_frames;
  d["unreadable_frames"] = r.unreadable;
  d["ground_truth"] = trajectory_arrays(r.tracking.ground_truth);
  const Intrinsics& K = r.intrinsics;
  d["intrinsics"] = py::dict(py::arg("fx") = K.fx, py::arg("fy") = K.fy, py::arg("cx") = K.cx, py::arg("cy") = K.cy,
                             py::arg("width") = K.width, py::arg("height") = K.height);
  if (r.volume) d["mesh"] = mesh_arrays(std::move(r.mesh));
  if (r.first_frame.depth.width() > 0) {
    py::dict f;
    f["timestamp"] = r.first_frame.timestamp;
    f["depth"] = owned_image<float>(std::move(r.first_frame.depth), 1);
    f["colour"] = owned_image<std::uint8_t>(std::move(r.first_frame.rgb), 3);
    d["first_frame"] = f;
  }
  return d;
}

// --- frames from Python ------------------------------------------------------------------------

// Copies a C-contiguous array (the Python side checked dtype and layout) into a host image.
template <class T> void copy_image(const py::array& a, Image<T>& im) {
  const auto h = static_cast<int>(a.shape(0)), w = static_cast<int>(a.shape(1));
  if (im.width() != w || im.height() != h || im.device() != Device::CPU) im = Image<T>(w, h, Device::CPU);
  std::memcpy(im.buffer().data(), a.data(), static_cast<std::size_t>(w) * h * sizeof(T));
}

// Each call of next() on the Python iterator gives (timestamp, depth float32 HxW, colour uint8
// HxWx3, accelerometer or None, camera-to-world 4x4 or None), checked on the Python side.
// A Python object that C++ may let go of without holding the GIL (the frame source is destroyed
// inside the run, which releases it).
struct Held {
  py::object object;
  explicit Held(py::object o) : object(std::move(o)) {}
  ~Held() {
    py::gil_scoped_acquire gil;
    object = py::object();
  }
};

CallbackSource::Fetch python_fetch(py::object iterator) {
  auto held = std::make_shared<Held>(std::move(iterator));
  return [held](RgbdFrame& frame) {
    py::gil_scoped_acquire gil;
    py::object item;
    try {
      item = held->object.attr("__next__")();
    } catch (py::error_already_set& e) {
      if (e.matches(PyExc_StopIteration)) return false;
      throw;
    }
    auto t = item.cast<py::tuple>();
    frame.timestamp = t[0].cast<double>();
    copy_image(t[1].cast<py::array>(), frame.depth);
    copy_image(t[2].cast<py::array>(), frame.rgb);
    if (!t[3].is_none()) {
      auto a = t[3].cast<std::vector<double>>();
      frame.accelerometer = vec3{static_cast<float>(a[0]), static_cast<float>(a[1]), static_cast<float>(a[2])};
    }
    if (!t[4].is_none()) {
      auto m = t[4].cast<py::array_t<double, py::array::c_style | py::array::forcecast>>();
      auto M = m.unchecked<2>();
      SE3 pose = SE3::identity();
      for (int r = 0; r < 3; ++r) {
        for (int c = 0; c < 3; ++c) pose.R.m[r][c] = static_cast<float>(M(r, c));
      }
      pose.t = {static_cast<float>(M(0, 3)), static_cast<float>(M(1, 3)), static_cast<float>(M(2, 3))};
      frame.ground_truth = pose;
    }
    return true;
  };
}

Intrinsics intrinsics_from(const py::dict& d) {
  Intrinsics K;
  K.fx = d["fx"].cast<float>(), K.fy = d["fy"].cast<float>(), K.cx = d["cx"].cast<float>();
  K.cy = d["cy"].cast<float>(), K.width = d["width"].cast<int>(), K.height = d["height"].cast<int>();
  if (d.contains("dist")) {
    auto dist = d["dist"].cast<std::vector<float>>();
    if (dist.size() > 5)
      throw ConfigError("intrinsics: dist has " + std::to_string(dist.size()) +
                        " coefficients; at most 5 (k1 k2 p1 p2 k3, OpenCV's order)");
    for (std::size_t i = 0; i < dist.size(); ++i) K.dist[i] = dist[i];
  }
  return K;
}

// --- running a subcommand ----------------------------------------------------------------------

struct Call {
  std::string command;            // track, reconstruct, run, simulate
  std::string config_path;        // a file, or empty with yaml_text
  std::string yaml_text;          // a config given as text (a dict dumped as JSON)
  std::vector<std::string> sets;  // as --set
  std::string out;
  bool force = false;
  py::object frames;      // None, or an iterator of frame tuples
  py::object intrinsics;  // None (the config's input.intrinsics), or a dict
  py::object size;        // None, or the number of frames
  py::object progress;    // None, or callable(what, done, total, status)
  std::string verbosity = "normal";
};

Experiment load(const std::string& config_path, const std::string& yaml_text, const std::vector<std::string>& sets) {
  return config_path.empty() ? parse_experiment(yaml_text, sets, "<dict>") : load_experiment(config_path, sets);
}

// Python keeps its own SIGINT handling: RunContext installs seamless's handlers (a Ctrl-C finishes
// the frame and writes the outputs), and they are put back afterwards.
class SignalGuard {
 public:
  SignalGuard() { sigaction(SIGINT, nullptr, &int_), sigaction(SIGTERM, nullptr, &term_); }
  ~SignalGuard() { sigaction(SIGINT, &int_, nullptr), sigaction(SIGTERM, &term_, nullptr); }

 private:
  struct sigaction int_ {
  }, term_{};
};

void set_verbosity(const std::string& v) {
  if (v != "quiet" && v != "normal" && v != "verbose")
    throw UsageError("verbosity is '" + v + "'; one of quiet, normal, verbose");
  init_logging(v == "quiet" ? Verbosity::Quiet : v == "verbose" ? Verbosity::Verbose : Verbosity::Normal);
}

py::dict run_call(Call& c) {
  set_verbosity(c.verbosity);
  Experiment e = load(c.config_path, c.yaml_text, c.sets);
  app::CommonOptions o;
  o.config = c.config_path.empty() ? "<dict>" : c.config_path;
  o.out = !c.out.empty() ? c.out : app::default_out_dir(e, c.config_path.empty() ? e.name : c.config_path);
  o.force = c.force;
  std::unique_ptr<FrameSource> source;
  if (!c.frames.is_none()) {
    if (c.command == "simulate") throw UsageError("seamless.simulate reads no frames: it runs on the synthetic room");
    // The offline refinement reads the input a second time; frames from Python come once.
    if (c.command == "track" && e.refine.enabled && !e.refine.online)
      throw UsageError(
          "refine.enabled reads the input a second time, and frames given from Python are read once: set "
          "refine.enabled: false, or refine.online: true (refined while tracking)");
    const Intrinsics K = c.intrinsics.is_none() ? resolve_intrinsics(e.input.intrinsics).K
                                                : intrinsics_from(c.intrinsics.cast<py::dict>());
    std::optional<std::int64_t> size;
    if (!c.size.is_none()) size = c.size.cast<std::int64_t>();
    source = std::make_unique<CallbackSource>(python_fetch(c.frames), K, e.input.undistort, size, e.input.max_frames,
                                              "frames from Python");
  }
  py::dict result;
  int exit_code = 0;
  bool stopped = false;
  {
    std::optional<app::ScanResult> scan;
    std::optional<app::SimulationResult> sim;
    std::optional<app::RunOutputs> run;
    std::vector<StageTimer::Row> timings;
    std::string out_dir;
    {
      SignalGuard signals;
      if (!c.progress.is_none()) {
        py::object cb = c.progress;
        set_progress_observer(
            [cb](const std::string& what, std::int64_t done, std::int64_t total, const std::string& status) {
              py::gil_scoped_acquire gil;
              cb(what, done, total, status);
            });
      }
      struct ClearObserver {
        ~ClearObserver() { set_progress_observer(nullptr); }
      } clear_observer;
      py::gil_scoped_release nogil;
      app::RunContext ctx(o, std::move(e));
      if (source) ctx.set_source(std::move(source));
      if (c.command == "track") scan = app::track_experiment(ctx);
      else if (c.command == "reconstruct") scan = app::reconstruct_experiment(ctx);
      else if (c.command == "simulate") sim = app::simulate_experiment(ctx);
      else run = app::run_experiment(ctx, o.config);
      timings = ctx.timer().rows();
      out_dir = ctx.out_dir();
      exit_code = ctx.exit_code();
      stopped = interrupted();
    }
    if (scan) result = scan_arrays(std::move(*scan));
    if (sim) {
      result["particles"] = particle_arrays(std::move(sim->state));
      result["solver"] = solver_stats(sim->stats);
    }
    if (run) {
      if (run->live) {
        result["frames"] = frame_records(run->live_frames);
      } else {
        result = scan_arrays(std::move(run->scan));
        const auto n = static_cast<py::ssize_t>(run->scene_particles.size());
        result["scene_particles"] = owned<float>(std::move(run->scene_particles), {n, 3});
        result["particles"] = particle_arrays(std::move(run->simulation.state));
        result["solver"] = solver_stats(run->simulation.stats);
      }
    }
    result["timings"] = timing_arrays(timings);
    result["out_dir"] = out_dir;
  }
  result["exit_code"] = exit_code;
  result["interrupted"] = stopped;
  return result;
}

// The frames a config's input section delivers, as arrays (seamless.frames()).
class FrameReader {
 public:
  FrameReader(const std::string& config_path, const std::string& yaml_text, const std::vector<std::string>& sets)
      : e_(load(config_path, yaml_text, sets)), source_(make_source(e_.input, Device::CPU)) {}
  py::object next() {
    RgbdFrame f;
    {
      py::gil_scoped_release nogil;
      if (!source_->next(f)) return py::none();
    }
    py::dict d;
    d["index"] = f.index, d["timestamp"] = f.timestamp;
    d["depth"] = owned_image<float>(std::move(f.depth), 1);
    d["colour"] = owned_image<std::uint8_t>(std::move(f.rgb), 3);
    d["accelerometer"] = f.accelerometer
                             ? py::object(py::make_tuple(f.accelerometer->x, f.accelerometer->y, f.accelerometer->z))
                             : py::none();
    if (f.ground_truth) {
      py::array_t<double> m({py::ssize_t{4}, py::ssize_t{4}});
      auto M = m.mutable_unchecked<2>();
      for (int r = 0; r < 4; ++r)
        for (int k = 0; k < 4; ++k) M(r, k) = r == 3 ? (k == 3 ? 1.0 : 0.0) : 0.0;
      for (int r = 0; r < 3; ++r) {
        for (int k = 0; k < 3; ++k) M(r, k) = f.ground_truth->R.m[r][k];
        M(r, 3) = (&f.ground_truth->t.x)[r];
      }
      d["ground_truth"] = m;
    } else {
      d["ground_truth"] = py::none();
    }
    return d;
  }
  py::dict intrinsics() const {
    const Intrinsics K = source_->intrinsics();
    return py::dict(py::arg("fx") = K.fx, py::arg("fy") = K.fy, py::arg("cx") = K.cx, py::arg("cy") = K.cy,
                    py::arg("width") = K.width, py::arg("height") = K.height,
                    py::arg("dist") = std::vector<float>(std::begin(K.dist), std::end(K.dist)));
  }
  py::object size() const {
    auto n = source_->size();
    return n ? py::object(py::int_(*n)) : py::none();
  }

 private:
  Experiment e_;
  std::unique_ptr<FrameSource> source_;
};

}  // namespace

PYBIND11_MODULE(_seamless, m) {
  m.doc() = "seamless: depth-camera tracking, TSDF reconstruction and particle physics (docs/PYTHON.md)";
  m.attr("__version__") = SEAMLESS_VERSION;
  m.attr("git_commit") = SEAMLESS_GIT_COMMIT;
  init_logging(Verbosity::Normal);

  // The CLI's exit codes by kind of failure become these exceptions, with the same messages.
  static py::exception<Error> error(m, "Error", PyExc_RuntimeError);
  static py::exception<ConfigError> config_error(m, "ConfigError", error.ptr());
  static py::exception<InputError> input_error(m, "InputError", error.ptr());
  static py::exception<UsageError> usage_error(m, "UsageError", error.ptr());
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const ConfigError& e) {
      config_error(e.what());
    } catch (const InputError& e) {
      input_error(e.what());
    } catch (const UsageError& e) {
      usage_error(e.what());
    } catch (const Error& e) {
      error(e.what());
    }
  });

  m.def(
      "run_command",
      [](const std::string& command, const std::string& config_path, const std::string& yaml_text,
         const std::vector<std::string>& sets, const std::string& out, bool force, py::object frames,
         py::object intrinsics, py::object size, py::object progress, const std::string& verbosity) {
        Call c{command, config_path, yaml_text, sets, out, force, frames, intrinsics, size, progress, verbosity};
        return run_call(c);
      },
      "runs track, reconstruct, simulate or run (use the wrappers in seamless)");
  m.def(
      "effective_config",
      [](const std::string& config_path, const std::string& yaml_text, const std::vector<std::string>& sets) {
        return to_yaml(load(config_path, yaml_text, sets));
      },
      "the loaded, validated config with every key (as `seamless config`)");
  m.def(
      "eval_report",
      [](const std::string& gt, const std::string& est, const std::string& align, double t_max_diff, double offset) {
        EvalOptions o;
        o.align = parse_alignment(align);
        o.t_max_diff = t_max_diff, o.offset = offset;
        return app::eval_report(gt, est, o);
      },
      "seamless eval's JSON text");
  m.attr("default_t_max_diff") = EvalOptions{}.t_max_diff;
  // What this build contains (build_config.hpp): the pip build has none of these.
  py::dict features;
  features["cuda"] = SEAMLESS_HAS_CUDA != 0, features["ceres"] = SEAMLESS_HAS_CERES != 0;
  features["opencv"] = SEAMLESS_HAS_OPENCV != 0, features["pcl"] = SEAMLESS_HAS_PCL != 0;
  features["gl"] = SEAMLESS_HAS_GL != 0, features["glfw"] = SEAMLESS_HAS_GLFW != 0;
  features["freenect"] = SEAMLESS_HAS_FREENECT != 0;
  m.attr("features") = features;
  py::class_<FrameReader>(m, "FrameReader")
      .def(py::init<const std::string&, const std::string&, const std::vector<std::string>&>())
      .def("next", &FrameReader::next)
      .def("intrinsics", &FrameReader::intrinsics)
      .def("size", &FrameReader::size);
}
