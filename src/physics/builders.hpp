// Host-side construction of particle objects from `spawn:` entries: fluid blocks, emitter
// layers, cloth sheets and rigid bodies (box, sphere, voxelised mesh). A builder returns a
// ParticleBatch in local indices; ParticleSolver::add_batch gives it ids and a group.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "core/math.hpp"
#include "kernels/physics/sim_views.hpp"
#include "physics/solver_params.hpp"

namespace seamless {

struct ParticleBatch {
  enum Kind { kFluid, kCloth, kRigid } kind = kFluid;
  std::vector<vec3> x, v;
  std::vector<float> inv_mass;
  std::vector<vec3> rest;  // rigid: body-frame offsets (sum zero); cloth: rest positions
  std::vector<vec4> rsdf;  // rigid: body-frame SDF gradient and value per particle
  // cloth topology (local indices)
  std::vector<int> edge_a, edge_b;
  std::vector<float> edge_len;
  std::vector<kernels::Quad> bends;
  std::vector<float> bend_rest;
  std::vector<int3> tris;
  float stretch_k = 1.f, bend_k = 0.f;
  float max_strain = 0.f;  // strain limit of every stretch edge (Provot 1995); 0 = none
  bool self_collide = false;
  // rigid body frame
  vec3 centre{0.f, 0.f, 0.f};
  vec4 rotation{0.f, 0.f, 0.f, 1.f};
  float stiffness = 1.f;
  std::int64_t size() const { return static_cast<std::int64_t>(x.size()); }
};

// Rotation from Euler angles (degrees) about x, then y, then z, as a quaternion (x, y, z, w).
vec4 euler_to_quat(vec3 degrees);

// A box of fluid filled on a cubic lattice of one diameter spacing, centred on s.position.
ParticleBatch make_fluid_block(const SpawnParams& s, const SolverParams& p);
// A sheet of nx x ny particles, spacing s.spacing (0: one diameter), centred on s.position,
// lying in the plane normal to gravity, then turned by s.rotation. Distance constraints on
// structural and shear edges, dihedral bending on every interior edge of the triangulation.
ParticleBatch make_cloth(const SpawnParams& s, const SolverParams& p);
// A rigid body: shape box (s.size), sphere (diameter s.size.x) or mesh (s.mesh, OBJ, scaled so
// that its bounding box fits s.size), posed by s.position and s.rotation, moving with s.velocity.
ParticleBatch make_rigid(const SpawnParams& s, const SolverParams& p);
// One layer of an emitter: a disc of particles of radius s.nozzle_radius normal to s.velocity.
ParticleBatch make_emitter_layer(const SpawnParams& s, const SolverParams& p);

// Number of particles a spawn entry will create (emitters: rate * duration; -1 if unbounded).
std::int64_t spawn_particle_count(const SpawnParams& s, const SolverParams& p);
// Throws seamless::Error naming the entry when the spawn list needs more than max_particles.
void check_spawn_capacity(const std::vector<SpawnParams>& spawns, const SolverParams& p);

// A triangle mesh read from an OBJ file: its vertices and its faces as triangles (polygons as fans
// around their first vertex), 0-based.
struct ObjMesh {
  std::vector<vec3> v;
  std::vector<int3> f;
};
// The OBJ reader of the project (rigid bodies' `shape: mesh`), through tinyobjloader (Debian's
// libtinyobjloader-dev): the vertices and faces of every object and group; normals, texture
// coordinates and materials are not used ('mtllib' files are not opened). Like the library, it
// reads a missing or unreadable vertex coordinate as 0 and a face vertex by its leading digits.
// Throws seamless::InputError naming the file and the problem (with the library's message and,
// where it tells one, the line): a missing file, a face vertex 0 or not a number, one that does
// not exist or counts back past the first vertex, a vertex that is not finite, no triangles.
ObjMesh read_obj(const std::string& path);

// Voxelises a closed triangle mesh (OBJ) on a grid of the given spacing: the centres inside by
// ray parity, in the mesh's own coordinates. Throws seamless::Error if the file cannot be read.
std::vector<vec3> voxelize_obj(const std::string& path, float spacing, vec3 fit_size);

}  // namespace seamless
