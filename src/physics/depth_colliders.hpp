// Kinematic collider particles from a depth camera's view (issue 22, solver.dynamic_colliders): a
// person or object the camera sees moving becomes, each frame, a set of infinitely heavy particles
// at its measured surface, so that the solver's ordinary scene contacts push fluid, cloth and rigid
// bodies out of it (Macklin et al. 2014's particle contacts, section 4.3; the idea of colliding
// particles with the live depth map is Google's DepthLab, Du et al. UIST 2020). The camera sees only
// the front of a body, so each point is extended along its camera ray by `thickness`: a particle
// pushed through the front layer meets the next one instead of ending inside the body.
#pragma once
#include <cstdint>
#include <vector>

#include "core/math.hpp"

namespace seamless {

// camera_vertices: a vertex map (camera coordinates, row-major, z <= 0 = no reading), width x
// height; mask: empty (every pixel) or one byte per pixel (nonzero = use it). Returns world points:
// each used pixel's point and, behind it along the ray from the camera, one more every `spacing`
// metres up to `thickness`.
std::vector<vec3> depth_collider_points(const std::vector<vec3>& camera_vertices, int width, int height,
                                        const SE3& world_T_camera, float spacing, float thickness,
                                        const std::vector<std::uint8_t>& mask = {});

}  // namespace seamless
