"""A TUM folder of the first `frames` associated pairs of a real recording, for the app tests:
images linked, not copied; the ground truth and accelerometer copied. `damage(i, src, dest)` may
write frame i's depth PNG itself (a covered sensor, a truncated file) and return True; otherwise
the frame's depth is linked like the rest."""
import os
import shutil


def tum_subset(tum, dest, frames, damage=None):
    with open(os.path.join(tum, "associations.txt")) as f:
        pairs = [line.split() for line in f if line.strip() and not line.startswith("#")][:frames]
    os.makedirs(os.path.join(dest, "rgb"))
    os.makedirs(os.path.join(dest, "depth"))
    with open(os.path.join(dest, "associations.txt"), "w") as f:
        for p in pairs:
            f.write(" ".join(p) + "\n")
    for i, (_, rgb, _, depth) in enumerate(pairs):
        os.symlink(os.path.join(tum, rgb), os.path.join(dest, rgb))
        if not (damage and damage(i, os.path.join(tum, depth), os.path.join(dest, depth))):
            os.symlink(os.path.join(tum, depth), os.path.join(dest, depth))
    for name in ["groundtruth.txt", "accelerometer.txt"]:
        shutil.copy(os.path.join(tum, name), dest)
