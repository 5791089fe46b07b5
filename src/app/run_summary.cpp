#include "app/run_summary.hpp"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

#include "core/error.hpp"
#include "eval/trajectory_eval.hpp"
#include "seamless/build_config.hpp"
#include "seamless/git_commit.hpp"

namespace seamless::app {

SceneBounds scene_bounds(const Mesh& mesh, vec3 up, const HorizontalSurface* floor) {
  SceneBounds b;
  b.up = up;
  if (floor) b.floor = floor->height;
  if (!mesh.positions.empty()) {
    b.lo = b.hi = mesh.positions[0];
    for (vec3 p : mesh.positions) b.lo = vmin(b.lo, p), b.hi = vmax(b.hi, p);
  }
  return b;
}

EscapedParticles count_escaped(const ParticleState& s, const SceneBounds& b, float diameter) {
  EscapedParticles e;
  const float margin = 2.f * diameter;
  const vec3 up = normalize(b.up);
  for (std::size_t i = 0; i < s.x.size(); ++i) {
    if (s.inv_mass[i] == 0.f) continue;  // pinned cloth corners stay where they were put
    const vec3 x = s.x[i];
    const float h = dot(x, up);
    if (b.floor && h < *b.floor - margin) ++e.below_floor;
    else if (x.x < b.lo.x - margin || x.y < b.lo.y - margin || x.z < b.lo.z - margin || x.x > b.hi.x + margin ||
             x.y > b.hi.y + margin || x.z > b.hi.z + margin)
      ++e.outside;
    else if (-dot(s.v[i], up) > kFallSpeed)
      ++e.falling;
  }
  return e;
}

void add_tracking(RunSummary& s, const TrackSequenceResult& r, std::int64_t unreadable,
                  const std::string& groundtruth) {
  s.frames_read = static_cast<std::int64_t>(r.frames.size());
  s.frames_lost = r.lost_frames;
  s.frames_unreadable = unreadable;
  for (const FrameRecord& f : r.frames) s.frames_fused += f.fused;
  if (groundtruth.empty() || r.trajectory.empty()) return;
  const AteResult ate = compute_ate(r.trajectory, read_tum_trajectory(groundtruth));
  if (ate.trans.count == 0) return;
  s.ate_rmse_m = ate.trans.rmse;
  s.ate_pairs = static_cast<std::int64_t>(ate.trans.count);
}

void add_stage_medians(RunSummary& s, const StageTimer& t) {
  std::set<std::string> stages;
  for (const StageTimer::Row& r : t.rows()) stages.insert(r.stage);
  for (const std::string& st : stages) s.stage_median_ms.push_back({st, t.median_ms(st)});
}

namespace {

// A minimal JSON writer: objects and arrays by hand, strings escaped (RFC 8259 section 7).
std::string quote(const std::string& v) {
  std::string out = "\"";
  for (unsigned char c : v) {
    if (c == '"' || c == '\\') out += '\\', out += static_cast<char>(c);
    else if (c == '\n') out += "\\n";
    else if (c == '\t') out += "\\t";
    else if (c < 0x20) {
      char buf[8];
      std::snprintf(buf, sizeof buf, "\\u%04x", c);
      out += buf;
    } else out += static_cast<char>(c);
  }
  return out + "\"";
}
std::string num(double v) {
  if (!std::isfinite(v)) return "null";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.9g", v);
  return buf;
}
std::string vec(vec3 v) { return "[" + num(v.x) + ", " + num(v.y) + ", " + num(v.z) + "]"; }

}  // namespace

void write_summary(const std::string& path, const RunSummary& s) {
  std::ostringstream j;
  j << "{\n  \"seamless_version\": " << quote(SEAMLESS_VERSION) << ",\n  \"commit\": " << quote(SEAMLESS_GIT_COMMIT)
    << ",\n  \"command\": " << quote(s.command) << ",\n  \"config\": " << quote(s.config)
    << ",\n  \"device\": " << quote(s.device) << ",\n";
  if (s.intrinsics) {
    const Intrinsics& K = *s.intrinsics;
    j << "  \"intrinsics\": {\"fx\": " << num(K.fx) << ", \"fy\": " << num(K.fy) << ", \"cx\": " << num(K.cx)
      << ", \"cy\": " << num(K.cy) << ", \"width\": " << K.width << ", \"height\": " << K.height << "},\n";
  }
  j << "  \"frames\": {\"read\": " << s.frames_read << ", \"lost\": " << s.frames_lost
    << ", \"fused\": " << s.frames_fused << ", \"unreadable\": " << s.frames_unreadable << "},\n";
  if (s.ate_rmse_m) j << "  \"ate\": {\"rmse_m\": " << num(*s.ate_rmse_m) << ", \"pairs\": " << s.ate_pairs << "},\n";
  if (s.floor_height) j << "  \"floor_height\": " << num(*s.floor_height) << ",\n";
  j << "  \"surfaces\": [";
  for (std::size_t i = 0; i < s.surfaces.size() && i < 10; ++i) {
    const HorizontalSurface& h = s.surfaces[i];
    j << (i ? ", " : "") << "{\"area_m2\": " << num(h.area) << ", \"height\": " << num(h.height)
      << ", \"centre\": " << vec(h.centre) << ", \"open_radius\": " << num(h.open_radius)
      << ", \"floor\": " << (h.floor ? "true" : "false") << "}";
  }
  j << "],\n";
  j << "  \"spawns\": [";
  for (std::size_t i = 0; i < s.spawns.size(); ++i) {
    const SpawnParams& sp = s.spawns[i];
    j << (i ? ",\n" : "\n") << "    {\"index\": " << i << ", \"kind\": " << quote(sp.kind)
      << ", \"time\": " << num(sp.time) << ", \"position\": " << vec(sp.position);
    for (const ResolvedPlacement& r : s.placements)
      if (r.spawn == static_cast<int>(i))
        j << ", \"placed\": " << quote(r.how) << ", \"surface_point\": " << vec(r.surface_point);
    j << "}";
  }
  j << (s.spawns.empty() ? "],\n" : "\n  ],\n");
  if (s.physics) {
    const SolverStats& p = *s.physics;
    j << "  \"particles\": {\"dynamic\": " << p.particles << ", \"fluid\": " << p.fluid_particles
      << ", \"cloth\": " << p.cloth_particles << ", \"rigid\": " << p.rigid_particles
      << ", \"rigid_bodies\": " << p.rigid_bodies << ", \"static\": " << p.static_particles
      << ", \"simulated_s\": " << num(p.time) << ", \"steps\": " << p.steps
      << ", \"neighbour_overflow\": " << p.neighbour_overflow << ", \"emitter_dropped\": " << p.emitter_dropped;
    if (s.escaped)
      j << ", \"escaped\": " << s.escaped->total() << ", \"escaped_below_floor\": " << s.escaped->below_floor
        << ", \"escaped_outside\": " << s.escaped->outside << ", \"escaped_falling\": " << s.escaped->falling;
    j << "},\n";
  }
  j << "  \"stage_median_ms\": {";
  for (std::size_t i = 0; i < s.stage_median_ms.size(); ++i)
    j << (i ? ", " : "") << quote(s.stage_median_ms[i].first) << ": " << num(s.stage_median_ms[i].second);
  j << "}\n}\n";

  const std::string tmp = path + ".tmp";
  {
    std::ofstream out(tmp);
    out << j.str();
    if (!out) throw Error("cannot write '" + tmp + "' (is the output folder writable?)");
  }
  std::filesystem::rename(tmp, path);
}

}  // namespace seamless::app
