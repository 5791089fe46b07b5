// The object file physics writes into a run's folder and `seamless render` reads back:
// objects.txt, which particles form which objects. The particle states themselves are PLY files
// (io/ply.hpp: write_particles_ply, read_particles_ply).
#pragma once
#include <string>

#include "core/particles.hpp"

namespace seamless {

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
