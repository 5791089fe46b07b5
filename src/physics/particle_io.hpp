// The files physics writes into a run's folder and `seamless render` reads back: particle states
// (particles.ply, particles_<step>.ply, scene_particles.ply) and the objects they form (objects.txt).
#pragma once
#include <string>

#include "core/particles.hpp"

namespace seamless {

// Writes particles as a binary little-endian PLY (x y z float, vx vy vz float, phase uint).
void write_particles_ply(const std::string& path, const ParticleState& s);
// Reads what write_particles_ply writes (inv_mass is not stored: 1). Throws seamless::Error naming
// the file when it is not such a file or is cut short.
ParticleState read_particles_ply(const std::string& path);

// objects.txt: which particles form cloth sheets and rigid bodies, and the bodies' rest offsets.
// Particle ids never change, so one file written at the end of a run serves every snapshot
// (objects spawned later have ids past the end of earlier snapshots). Text, one record a line:
//   # comment
//   cloth_triangles <n>            followed by n lines "a b c" (particle ids; every sheet's)
//   body <first> <count> <spawn>   followed by count lines "qx qy qz" (rest offsets, metres)
// Meshes are not stored (attach_body_meshes makes them from the spawn list again); the sheets are
// read back as one ClothSheet of unknown range.
void write_objects(const std::string& path, const SceneObjects& o);
// Throws seamless::Error naming the file and line.
SceneObjects read_objects(const std::string& path);

}  // namespace seamless
