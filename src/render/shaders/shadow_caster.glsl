// Placed first in the vertex shaders that draw casters into the shadow map (renderer_shadow.cpp):
// mesh.vert and cloth.vert then place vertices with light_clip() instead of the camera.
#define SEAMLESS_SHADOW_CASTER 1
