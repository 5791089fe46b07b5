// Contact occlusion: the room's light that the virtual rigid bodies hide from a real surface (the
// Kinect view's image; the scan in the mesh view is left without: on the CPU's GL its fragments,
// at 1280 x 720 and drawn over each other, took half a second a frame of the demo).
// The directional light's share of a real surface's light (shadow_strength) is darkened by the
// shadow map (shadow.glsl); the rest comes from the room (windows, ceiling, walls), which a body
// standing on the surface hides in part. Taking that light as uniform over the hemisphere, the
// share hidden at a point p with normal n is the form factor from p to the body (the
// cosine-weighted solid angle it covers, over pi): dark under and beside its base, fading with
// distance, the contact shadow a real object leaves where the map's hard light leaves none.
// Bodies are their boxes (RigidDraw's box, or a mesh's bounds) in their own frame.
uniform int u_occluder_count;
// Box k in row k, 4 RGBA32F texels: the rows of world -> the box's frame (axis-aligned, centred)
// as [R | t], then the half extents (metres); uploaded once a frame (renderer_shadow.cpp).
uniform sampler2D u_boxes;

// Lambert's contour term of the edge from unit direction a to unit direction b: the angle between
// them times the cosine, to the normal n, of the plane they span (n . unit(a x b)).
float edge_term(vec3 n, vec3 a, vec3 b) {
  vec3 c = cross(a, b);
  float l = length(c);
  return l > 1e-9 ? acos(clamp(dot(a, b), -1.0, 1.0)) * dot(n, c) / l : 0.0;
}

// The edge from a to b (relative to the point) of a polygon clipped to the point's horizon
// n . x >= 0 (Sutherland & Hodgman 1974): its part above the horizon, and where it leaves or
// enters it; the clipped polygon closes along the horizon from the exit to the entry.
float clipped_edge(vec3 n, vec3 a, vec3 b, inout vec3 exit_at, inout vec3 entry_at) {
  float da = dot(n, a), db = dot(n, b);
  if (da >= 0.0 && db >= 0.0) return edge_term(n, normalize(a), normalize(b));
  if (da < 0.0 && db < 0.0) return 0.0;
  vec3 x = a + (b - a) * (da / (da - db));
  if (da >= 0.0) {
    exit_at = x;
    return edge_term(n, normalize(a), normalize(x));
  }
  entry_at = x;
  return edge_term(n, normalize(x), normalize(b));
}

// Form factor from a differential area at the origin (unit normal n) to a planar quad, by
// Lambert's contour integral: F = 1 / (2 pi) sum_i gamma_i n . unit(v_i x v_(i+1)), v_i the unit
// directions to the corners, gamma_i the angle between consecutive ones (as in Baum, Rushmeier &
// Winget 1989, "Improving radiosity solutions through the use of analytically determined
// form-factors"). The corners (relative to the point) run counter-clockwise about the direction
// from the point to the quad, so F > 0. The point sees only what lies above its plane, so the
// quad is clipped to n . x >= 0 first. Straight-line code without arrays: llvmpipe ran a version
// with local arrays many times slower, whether or not a body was near.
float quad_form_factor(vec3 n, vec3 c0, vec3 c1, vec3 c2, vec3 c3) {
  vec3 exit_at = vec3(0.0), entry_at = vec3(0.0);
  float s = clipped_edge(n, c0, c1, exit_at, entry_at) + clipped_edge(n, c1, c2, exit_at, entry_at) +
            clipped_edge(n, c2, c3, exit_at, entry_at) + clipped_edge(n, c3, c0, exit_at, entry_at);
  if (dot(exit_at, exit_at) > 0.0 && dot(entry_at, entry_at) > 0.0)
    s += edge_term(n, normalize(exit_at), normalize(entry_at));
  return max(s, 0.0) / 6.2831853;
}

// Corner i of a box of half extents h, relative to the point q: (+-h.x, +-h.y, +-h.z) - q, the
// sign + where bit 0 (x), 1 (y), 2 (z) of i is set.
vec3 box_corner(int i, vec3 h, vec3 q) {
  return vec3((i & 1) != 0 ? h.x : -h.x, (i & 2) != 0 ? h.y : -h.y, (i & 4) != 0 ? h.z : -h.z) - q;
}

// The form factor from q to the box face of corners i0..i3 (counter-clockwise about the
// direction from an outside point to the face), seen from q with unit normal m (box frame).
float face_form_factor(vec3 m, vec3 q, vec3 h, int i0, int i1, int i2, int i3) {
  return quad_form_factor(m, box_corner(i0, h, q), box_corner(i1, h, q), box_corner(i2, h, q),
                          box_corner(i3, h, q));
}

// The form factor from p (world, unit world normal n) to box k: the sum over the faces p sees
// (a convex box's faces seen from outside do not overlap).
float box_form_factor(int k, vec3 p, vec3 n) {
  vec4 r0 = texelFetch(u_boxes, ivec2(0, k), 0), r1 = texelFetch(u_boxes, ivec2(1, k), 0),
       r2 = texelFetch(u_boxes, ivec2(2, k), 0);
  vec3 q = vec3(dot(r0.xyz, p) + r0.w, dot(r1.xyz, p) + r1.w, dot(r2.xyz, p) + r2.w);
  vec3 m = vec3(dot(r0.xyz, n), dot(r1.xyz, n), dot(r2.xyz, n)), h = texelFetch(u_boxes, ivec2(3, k), 0).xyz;
  // Far away the box lies in its bounding sphere (radius |h|), whose form factor from a distance
  // |q| is at most |h|^2 / |q|^2: under 1/256 beyond 16 |h|, a change of 0.2 % of the colour at
  // most (the room's share, half of it), so left out; so is a box wholly below p's plane (its
  // highest corner along m is -q . m + |m| . h).
  if (dot(q, q) > 256.0 * dot(h, h) || dot(abs(m), h) - dot(m, q) <= 0.0) return 0.0;
  // A face is seen from beyond its plane. Corner orders: x- 0 2 6 4, x+ 5 7 3 1, y- 0 4 5 1,
  // y+ 3 7 6 2, z- 0 1 3 2, z+ 6 7 5 4.
  float f = 0.0;
  if (-q.x > h.x) f += face_form_factor(m, q, h, 0, 2, 6, 4);
  if (q.x > h.x) f += face_form_factor(m, q, h, 5, 7, 3, 1);
  if (-q.y > h.y) f += face_form_factor(m, q, h, 0, 4, 5, 1);
  if (q.y > h.y) f += face_form_factor(m, q, h, 3, 7, 6, 2);
  if (-q.z > h.z) f += face_form_factor(m, q, h, 0, 1, 3, 2);
  if (q.z > h.z) f += face_form_factor(m, q, h, 6, 7, 5, 4);
  return f;
}

// The share of the room's light the bodies hide from p (world, unit world normal n), 0..1.
float occluded_share(vec3 p, vec3 n) {
  float f = 0.0;
  for (int k = 0; k < u_occluder_count; ++k) f += box_form_factor(k, p, n);
  return min(f, 1.0);
}
