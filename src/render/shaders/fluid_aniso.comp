// Anisotropic kernels for the fluid's surface (Yu & Turk 2013, "Reconstructing surfaces of
// particle-based fluids using anisotropic kernels", section 4): each fluid particle is splatted
// as an ellipsoid shaped like its neighbourhood instead of a sphere. Particles spread over a
// surface have their neighbours in a plane, so their ellipsoids flatten into overlapping discs:
// one continuous, flat sheet where spheres a few radii apart leave a bump per particle and a hole
// between them. Inside a body of water the neighbourhood is isotropic and the ellipsoid stays
// the sphere. Needs camera.glsl, sphere_hit.glsl (u_radius: the sphere radius) and splat.glsl
// (particle buffers, particle_index) before it.
//
// Stage 1 (u_stage 1) puts every fluid particle into a hashed uniform grid of cell size u_h
// (bucket counts cleared by the host before); stage 2 gathers each particle's neighbours within
// u_h from the 27 cells around it and writes its ellipsoid (splat.glsl, b_ell).
layout(std430, binding = 3) buffer BucketCount { uint b_bucket_count[]; };
layout(std430, binding = 4) buffer BucketSlots { uint b_bucket_slot[]; };
layout(std430, binding = 5) writeonly buffer EllipsoidsOut { vec4 b_ell_out[]; };

uniform int u_stage;
uniform uint u_buckets;    // hash table size, a power of two
uniform uint u_bucket_cap; // particles a bucket holds; more are left out of the neighbourhoods
uniform float u_h;         // neighbourhood radius and cell size, metres

// Yu & Turk's constants (section 4): an axis at most k_r times shorter than the longest, and
// at least N_eps neighbours for a shape. Their N_eps (25) is for a neighbourhood of about twice
// the particle spacing in bulk; here it must also hold for a spread layer, whose ring within
// three spacings has about ten: a particle with fewer than 6 has no meaningful plane and stays a
// sphere (a lone drop, the tip of a filament).
const float kMaxAxisRatio = 4.0;
const int kMinNeighbours = 6;
// Their smoothing of the kernel centres towards the neighbourhood's weighted mean (section 5,
// lambda = 0.9 in the paper): it flattens a layer whose particles lie at slightly different
// heights, which is most of the remaining bumpiness; kept below theirs because their kernel
// centres feed an isosurface, ours are drawn directly and a puddle's rim would shrink by most of
// a neighbourhood.
const float kCentreSmoothing = 0.5;

vec3 particle_pos(uint i) { return vec3(b_pos[3u * i], b_pos[3u * i + 1u], b_pos[3u * i + 2u]); }
bool is_fluid(uint i) { return (b_phase[i] & u_phase_mask) != 0u; }
ivec3 cell_of(vec3 x) { return ivec3(floor(x / u_h)); }
uint bucket_of(ivec3 c) {  // Teschner et al. 2003's spatial hash
  return (uint(c.x) * 73856093u ^ uint(c.y) * 19349663u ^ uint(c.z) * 83492791u) & (u_buckets - 1u);
}

// Symmetric 3 x 3 A = V diag(e) V^T by cyclic Jacobi rotations (each zeroes one off-diagonal
// element, Golub & Van Loan 8.5); 3 x 3 converges to float precision in a few sweeps.
void eigen_sym3(mat3 A, out mat3 V, out vec3 e) {
  V = mat3(1.0);
  for (int sweep = 0; sweep < 6; ++sweep)
    for (int k = 0; k < 3; ++k) {
      int p = k == 2 ? 1 : 0, q = k == 0 ? 1 : 2;  // (0,1), (0,2), (1,2)
      float apq = A[q][p];
      if (abs(apq) < 1e-20) continue;
      float theta = (A[q][q] - A[p][p]) / (2.0 * apq);
      float t = (theta >= 0.0 ? 1.0 : -1.0) / (abs(theta) + sqrt(theta * theta + 1.0));
      float c = inversesqrt(t * t + 1.0), s = t * c;
      mat3 J = mat3(1.0);  // GLSL indexes [column][row]: J_pq = s, J_qp = -s
      J[p][p] = c, J[q][q] = c, J[q][p] = s, J[p][q] = -s;
      A = transpose(J) * A * J;
      V = V * J;
    }
  e = vec3(A[0][0], A[1][1], A[2][2]);
}

void insert(uint i) {
  uint b = bucket_of(cell_of(particle_pos(i)));
  uint k = atomicAdd(b_bucket_count[b], 1u);
  if (k < u_bucket_cap) b_bucket_slot[b * u_bucket_cap + k] = i;
}

void shape(uint i) {
  vec3 xi = particle_pos(i);
  ivec3 ci = cell_of(xi);
  // Weighted moments of the neighbours' offsets y = x_j - x_i, weight 1 - (d / h)^3 (Yu & Turk
  // eq. 11), the particle itself included.
  float sw = 0.0;
  vec3 sy = vec3(0.0);
  mat3 syy = mat3(0.0);
  int neighbours = 0;
  for (int dz = -1; dz <= 1; ++dz)
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx) {
        ivec3 c = ci + ivec3(dx, dy, dz);
        uint b = bucket_of(c);
        uint n = min(b_bucket_count[b], u_bucket_cap);
        for (uint k = 0u; k < n; ++k) {
          uint j = b_bucket_slot[b * u_bucket_cap + k];
          vec3 xj = particle_pos(j);
          if (cell_of(xj) != c) continue;  // another cell hashed to this bucket
          vec3 y = xj - xi;
          float d = length(y);
          if (d >= u_h) continue;
          float q = d / u_h, w = 1.0 - q * q * q;
          sw += w, sy += w * y, syy += w * outerProduct(y, y);
          neighbours += j != i ? 1 : 0;
        }
      }
  vec3 centre = xi;
  mat3 M = mat3(1.0 / (u_radius * u_radius));
  float bound = u_radius;
  if (neighbours >= kMinNeighbours) {
    vec3 mean = sy / sw;
    mat3 C = syy / sw - outerProduct(mean, mean);  // weighted covariance (eq. 10)
    mat3 V;
    vec3 e;
    eigen_sym3(C, V, e);
    // Axes in proportion to the standard deviations along the principal directions, none below
    // 1 / kMaxAxisRatio of the longest (eq. 12's clamp), scaled to the sphere's volume so that
    // the summed chords stay a path length in fluid (ssfr_thickness_splat.comp).
    vec3 sd = sqrt(max(e, vec3(0.0)));
    float longest = max(sd.x, max(sd.y, sd.z));
    if (longest > 0.0) {
      sd = max(sd, vec3(longest / kMaxAxisRatio));
      vec3 axes = u_radius * sd / pow(sd.x * sd.y * sd.z, 1.0 / 3.0);
      M = V * mat3(1.0 / (axes.x * axes.x), 0.0, 0.0, 0.0, 1.0 / (axes.y * axes.y), 0.0, 0.0, 0.0,
                   1.0 / (axes.z * axes.z)) * transpose(V);
      bound = max(axes.x, max(axes.y, axes.z));
      centre = xi + kCentreSmoothing * mean;
    }
  }
  b_ell_out[3u * i] = vec4(centre, bound);
  b_ell_out[3u * i + 1u] = vec4(M[0][0], M[0][1], M[0][2], M[1][1]);
  b_ell_out[3u * i + 2u] = vec4(M[1][2], M[2][2], 0.0, 0.0);
}

void main() {
  uint i = particle_index();
  if (i >= u_count || !is_fluid(i)) return;
  if (u_stage == 1) insert(i);
  else shape(i);
}
