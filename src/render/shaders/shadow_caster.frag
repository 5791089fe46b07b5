// Shadow map casters (rigid meshes, cloth): depth only, written by the rasteriser.
void main() {}
