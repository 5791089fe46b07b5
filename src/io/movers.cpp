#include "io/movers.hpp"

#include <cmath>
#include <cstdio>
#include <numbers>

#include "core/error.hpp"

namespace seamless {

namespace {

// Where along the polyline (x, y on the floor) the mover is after travelling s metres, and the
// unit direction it faces; false once s passes the path's end.
bool along_path(const std::vector<vec3>& path, float s, vec3* at, vec3* facing) {
  for (std::size_t i = 0; i + 1 < path.size(); ++i) {
    const vec3 a{path[i].x, path[i].y, 0.f}, b{path[i + 1].x, path[i + 1].y, 0.f};
    const float len = length(b - a);
    if (len <= 0.f) continue;
    if (s <= len) {
      *facing = (b - a) / len;
      *at = a + *facing * s;
      return true;
    }
    s -= len;
  }
  return false;
}

// A person of height H walking: one gait cycle (two steps of 0.4 H) per 0.8 H travelled; legs
// swing +-0.45 rad about the hips, arms +-0.35 rad in opposition (a plain pendulum gait, enough to
// give the depth camera moving limbs). Proportions after the usual artists' canon.
// Appends one capsule; the renderer takes at most kMaxCapsules a frame.
void push(kernels::movers::Scene& s, const kernels::movers::Capsule& c) {
  if (s.count == kernels::movers::kMaxCapsules)
    throw ConfigError("input.synthetic.movers: more than " + std::to_string(kernels::movers::kMaxCapsules) +
                      " capsules in view at once (a person takes 6, a ball 1)");
  s.c[s.count++] = c;
}

void add_person(kernels::movers::Scene& s, int id, vec3 at, vec3 facing, float travelled, float H) {
  const vec3 up{0.f, 0.f, 1.f}, side = cross(facing, up);  // side: the person's right
  const float phase = 2.f * std::numbers::pi_v<float> * travelled / (0.8f * H);
  const float leg_swing = 0.45f * std::sin(phase), arm_swing = -0.35f * std::sin(phase);
  const vec3 shirt{0.2f, 0.35f, 0.65f}, trousers{0.15f, 0.15f, 0.22f}, skin{0.85f, 0.62f, 0.5f};
  const float leg_r = 0.035f * H, arm_r = 0.026f * H, hip_z = 0.53f * H, shoulder_z = 0.81f * H;
  auto add = [&](vec3 a, vec3 b, float r, vec3 albedo) { push(s, {a, b, r, id, albedo}); };
  const vec3 pelvis = at + up * hip_z;
  add(pelvis + up * 0.04f * H, at + up * (shoulder_z - 0.03f * H), 0.09f * H, shirt);  // torso
  add(at + up * 0.93f * H, at + up * 0.93f * H, 0.065f * H, skin);                     // head
  for (int k = -1; k <= 1; k += 2) {                                                   // left, right
    const vec3 hip = pelvis + side * (k * 0.055f * H);
    const float a = k * leg_swing, leg = hip_z - leg_r;  // the foot's sphere touches the floor at rest
    add(hip, hip + facing * (leg * std::sin(a)) - up * (leg * std::cos(a)), leg_r, trousers);
    const vec3 shoulder = at + up * shoulder_z + side * (k * 0.13f * H);
    const float b = k * arm_swing, arm = 0.36f * H;
    add(shoulder, shoulder + facing * (arm * std::sin(b)) - up * (arm * std::cos(b)), arm_r, shirt);
  }
}

}  // namespace

kernels::movers::Scene pose_movers(const std::vector<MoverParams>& movers, double t) {
  kernels::movers::Scene s;
  for (std::size_t i = 0; i < movers.size(); ++i) {
    const MoverParams& m = movers[i];
    float total = 0.f;
    for (std::size_t k = 0; k + 1 < m.path.size(); ++k)
      total += length(vec3{m.path[k + 1].x - m.path[k].x, m.path[k + 1].y - m.path[k].y, 0.f});
    if (total <= 0.f)
      throw ConfigError("input.synthetic.movers[" + std::to_string(i) +
                        "].path: needs at least two distinct points on the floor, [[x, y, 0], [x, y, 0], ...]");
    if (t < m.start) continue;
    const float travelled = static_cast<float>((t - m.start) * m.speed);
    vec3 at, facing;
    if (!along_path(m.path, travelled, &at, &facing)) continue;  // it has left
    const int id = static_cast<int>(i) + 1;
    if (m.kind == MoverKind::ball) {
      const vec3 c = at + vec3{0.f, 0.f, m.radius};
      push(s, {c, c, m.radius, id, {0.9f, 0.4f, 0.1f}});
    } else {
      add_person(s, id, at, facing, travelled, m.height);
    }
  }
  return s;
}

std::string movers_lines(double timestamp, const kernels::movers::Scene& s) {
  std::string out;
  char line[256];
  for (int i = 0; i < s.count; ++i) {
    const auto& c = s.c[i];
    std::snprintf(line, sizeof line, "%.6f %d %.5f %.5f %.5f %.5f %.5f %.5f %.5f\n", timestamp, c.mover, c.a.x, c.a.y,
                  c.a.z, c.b.x, c.b.y, c.b.z, c.r);
    out += line;
  }
  return out;
}

std::vector<int> mover_ids(const std::vector<MoverParams>& movers, MoverKind kind) {
  std::vector<int> ids;
  for (std::size_t i = 0; i < movers.size(); ++i)
    if (movers[i].kind == kind) ids.push_back(static_cast<int>(i) + 1);
  return ids;
}

}  // namespace seamless
