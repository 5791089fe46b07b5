#!/usr/bin/python3
"""Every #include of src/ and kernels/ against the allowed layer matrix.

    core  <-  kernels  <-  io, recon, physics, eval  <-  app        (config beside)
    core, io, physics  <-  render  <-  app    (render includes no kernel family; from physics
                                              it takes the fluid's ellipsoids, fluid_ellipsoids.hpp)

A layer may include itself and the layers its CMake targets link (the matrix below, which
mirrors src/*/CMakeLists.txt). Kernel families (kernels/io, kernels/physics, kernels/recon) may
include kernels/scene (the analytic scenes that several families evaluate) and core, not each
other. config reads every layer's parameters: it may include their *_params.hpp headers, nothing
else of them. A leak fails with the file, line and include.

usage: layers_test.py SOURCE_DIR
"""
import os
import re
import sys
import unittest

SRC = sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(__file__), "..", "..")

KERNEL_FAMILIES = {"kernels/io", "kernels/physics", "kernels/recon"}
ALLOWED = {
    "core": set(),
    "kernels/scene": {"core"},
    **{k: {"core", "kernels/scene"} for k in KERNEL_FAMILIES},
    "io": {"core", "kernels"},
    "recon": {"core", "kernels", "io"},
    "physics": {"core", "kernels"},
    "render": {"core", "io", "physics"},  # phase flags and quaternions are core's: no kernel family
    "eval": {"core", "io"},
    "config": {"core"},
    "app": {"core", "kernels", "io", "recon", "physics", "render", "eval", "config"},
}
PARAMS_FOR_CONFIG = {"io", "recon", "physics", "render"}
INCLUDE = re.compile(r'\s*#\s*include\s+"([^"]+)"')


def layer_of(rel):
    """Layer of a path relative to the source root (src/x/..., kernels/x/...) or of an include."""
    parts = rel.split("/")
    if parts[0] == "src":
        parts = parts[1:]
    if parts[0] == "kernels":
        return "kernels/" + parts[1] if len(parts) > 2 else "kernels"
    return parts[0] if parts[0] in ALLOWED else None


def allowed(src_layer, inc_layer, inc):
    if inc_layer is None or inc_layer == src_layer:
        return True
    ok = ALLOWED[src_layer]
    if inc_layer in ok or (inc_layer.startswith("kernels/") and "kernels" in ok):
        return True
    return src_layer == "config" and inc_layer in PARAMS_FOR_CONFIG and inc.endswith("_params.hpp")


def leaks(root):
    found = []
    for top in ("src", "kernels"):
        for dirpath, _, files in os.walk(os.path.join(root, top)):
            for f in sorted(files):
                if not f.endswith((".hpp", ".cpp", ".inl", ".cu", ".cuh", ".h")):
                    continue
                path = os.path.join(dirpath, f)
                rel = os.path.relpath(path, root)
                src_layer = layer_of(rel)
                if src_layer is None:
                    continue
                with open(path, errors="replace") as fh:
                    for n, line in enumerate(fh, 1):
                        m = INCLUDE.match(line)
                        if m and not allowed(src_layer, layer_of(m.group(1)), m.group(1)):
                            found.append(f"{rel}:{n}: {src_layer} includes {m.group(1)}")
    return found


class Layers(unittest.TestCase):
    def test_the_checker_sees_a_leak(self):
        # The rules themselves: what must be refused is refused.
        self.assertFalse(allowed("render", "recon", "recon/volume.hpp"))
        self.assertTrue(allowed("render", "physics", "physics/fluid_ellipsoids.hpp"))
        self.assertFalse(allowed("render", "kernels/physics", "kernels/physics/particle_math.hpp"))
        self.assertFalse(allowed("kernels/physics", "kernels/io", "kernels/io/render_room.hpp"))
        self.assertFalse(allowed("recon", "config", "config/config.hpp"))
        self.assertFalse(allowed("config", "recon", "recon/volume.hpp"))
        self.assertFalse(allowed("core", "kernels/recon", "kernels/recon/tsdf.hpp"))
        self.assertTrue(allowed("config", "recon", "recon/volume_params.hpp"))
        self.assertTrue(allowed("app", "render", "render/renderer.hpp"))

    def test_no_include_crosses_the_layers(self):
        found = leaks(SRC)
        self.assertEqual(found, [], "includes that break the layer matrix (tests/layers/layers_test.py):\n" +
                         "\n".join(found))


if __name__ == "__main__":
    unittest.main(argv=[sys.argv[0], "-v"])
