// Contact occlusion: the room's light that the virtual rigid bodies hide from a real surface.
// The directional light's share of a real surface's light (shadow_strength) is darkened by the
// shadow map (shadow.glsl); the rest comes from the room (windows, ceiling, walls), which a body
// standing on the surface hides in part. Taking that light as uniform over the hemisphere, the
// share hidden at a point p with normal n is the form factor from p to the body (the
// cosine-weighted solid angle it covers, over pi): dark under and beside its base, fading with
// distance, the contact shadow a real object leaves where the map's hard light leaves none.
// Bodies are their boxes (RigidDraw's box, or a mesh's bounds) in their own frame.
const int kMaxOccluders = 16;
uniform int u_occluder_count;
uniform mat4 u_box_T_world[kMaxOccluders];  // world -> the box's frame (axis-aligned, centred)
uniform vec3 u_box_half[kMaxOccluders];     // half extents, metres

// Form factor from a differential area at the origin (unit normal n) to a planar polygon, by
// Lambert's contour integral: F = 1 / (2 pi) sum_i gamma_i n . unit(v_i x v_(i+1)), v_i the unit
// directions to the corners, gamma_i the angle between consecutive ones (as in Baum, Rushmeier &
// Winget 1989, "Improving radiosity solutions through the use of analytically determined
// form-factors"). The corners c (relative to the point) run counter-clockwise about the
// direction from the point to the polygon, so F > 0. The point sees only what lies above its
// plane, so the quad is first clipped to n . x >= 0 (Sutherland & Hodgman 1974: one plane cuts a
// quad into at most 5 corners).
float quad_form_factor(vec3 n, vec3 c[4]) {
  vec3 v[5];
  int m = 0;
  for (int i = 0; i < 4; ++i) {
    vec3 a = c[i], b = c[(i + 1) & 3];
    float da = dot(n, a), db = dot(n, b);
    if (da >= 0.0) v[m++] = a;
    if ((da >= 0.0) != (db >= 0.0)) v[m++] = a + (b - a) * (da / (da - db));
  }
  float s = 0.0;
  for (int i = 0; i < m; ++i) {
    vec3 a = normalize(v[i]), b = normalize(v[(i + 1) % m]), c = cross(a, b);
    float l = length(c);
    if (l > 1e-9) s += acos(clamp(dot(a, b), -1.0, 1.0)) * dot(n, c) / l;
  }
  return max(s, 0.0) / 6.2831853;
}

// The form factor from p (world, unit world normal n) to box k: the sum over the faces p sees
// (a convex box's faces seen from outside do not overlap). Face (axis a, side s) has its corners
// at +-h along the other two axes, ordered counter-clockwise about -s e_a, the direction from
// an outside point to the face.
float box_form_factor(int k, vec3 p, vec3 n) {
  vec3 q = (u_box_T_world[k] * vec4(p, 1.0)).xyz, m = mat3(u_box_T_world[k]) * n, h = u_box_half[k];
  float f = 0.0;
  for (int a = 0; a < 3; ++a)
    for (int side = -1; side <= 1; side += 2) {
      float s = float(side);
      if (s * q[a] <= h[a]) continue;  // p is behind this face's plane: the face is not seen
      int i = (a + 1) % 3, j = (a + 2) % 3;  // e_i x e_j = e_a
      vec3 c[4];
      for (int t = 0; t < 4; ++t) {
        // (-,-), (+,-), (+,+), (-,+) is counter-clockwise about +e_a: the order for s = -1.
        float u = (t == 1 || t == 2) ? 1.0 : -1.0, w = t >= 2 ? 1.0 : -1.0;
        if (side > 0) w = -w;  // reversed (a mirror across e_i's plane) for s = +1
        vec3 corner;
        corner[a] = s * h[a], corner[i] = u * h[i], corner[j] = w * h[j];
        c[t] = corner - q;
      }
      f += quad_form_factor(m, c);
    }
  return f;
}

// The share of the room's light the bodies hide from p (world, unit world normal n), 0..1.
float occluded_share(vec3 p, vec3 n) {
  float f = 0.0;
  for (int k = 0; k < u_occluder_count; ++k) f += box_form_factor(k, p, n);
  return min(f, 1.0);
}
