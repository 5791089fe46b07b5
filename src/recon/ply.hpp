// Binary PLY (little endian) for meshes: vertices with position, normal and colour, triangles.
#pragma once
#include <string>

#include "recon/volume.hpp"

namespace seamless {

// Writes mesh to path; throws Error naming the path when it cannot be written.
void write_ply(const std::string& path, const Mesh& mesh);
// Reads a binary little-endian PLY with float x y z, optional float nx ny nz, optional uchar
// red green blue (in any order, other vertex properties skipped when they are float/uchar) and a
// face list of uchar count + int/uint indices, triangles only. Throws Error naming path and what
// is unsupported otherwise.
Mesh read_ply(const std::string& path);

}  // namespace seamless
