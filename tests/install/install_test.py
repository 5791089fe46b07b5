#!/usr/bin/python3
"""`cmake --install` gives PREFIX/bin/seamless, the configs and docs under
PREFIX/share/seamless and a CMake package that a project outside the tree builds on
(tests/install/consumer: find_package(seamless), seamless::core, ::kernels, ::io, ::eval, each
used once against a known answer).

usage: install_test.py BUILD_DIR SOURCE_DIR WORK_DIR VERSION   (about a minute on 2 cores)
"""
import os
import shutil
import subprocess
import sys


def run(*cmd, **kw):
    print(" ".join(cmd), flush=True)
    return subprocess.run(cmd, check=True, text=True, **kw)


def main():
    build, src, work, version = sys.argv[1:5]
    shutil.rmtree(work, ignore_errors=True)
    prefix = os.path.join(work, "prefix")
    run("cmake", "--install", build, "--prefix", prefix, stdout=subprocess.DEVNULL)
    exe = os.path.join(prefix, "bin", "seamless")
    out = run(exe, "--version", capture_output=True).stdout
    assert version in out, f"seamless --version printed {out!r}, expected {version}"
    share = os.path.join(prefix, "share", "seamless")
    for f in ("configs/demo.yaml", "configs/tum_fr2.yaml", "docs/ARCHITECTURE.md", "LICENSE", "CHANGELOG.md",
              "README.md"):
        assert os.path.isfile(os.path.join(share, f)), f"{f} is not installed under {share}"
    # The installed binary finds its configs without the source tree.
    run(exe, "config", os.path.join(share, "configs", "demo.yaml"), stdout=subprocess.DEVNULL)
    consumer = os.path.join(work, "consumer")
    gen = ["-G", "Ninja"] if shutil.which("ninja") else []
    run("cmake", "-S", os.path.join(src, "tests", "install", "consumer"), "-B", consumer, *gen,
        f"-DCMAKE_PREFIX_PATH={prefix}", "-DCMAKE_BUILD_TYPE=Release", stdout=subprocess.DEVNULL)
    run("cmake", "--build", consumer, "-j", "2")
    run(os.path.join(consumer, "consumer"))
    print("installed; the consumer project built on find_package(seamless) and its checks passed")
    return 0


if __name__ == "__main__":
    sys.exit(main())
