"""Shared fixtures: the C reference program (python/tests/reference.c, built by meson) and the
README. Under `meson test` their paths come from the environment; run by hand, they are looked
up in ../../build (python/meson.build sets everything up)."""
import os
import subprocess

import numpy as np
import pytest

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.normpath(os.path.join(HERE, "..", ".."))


def _path(env, default):
    p = os.environ.get(env) or default
    if not os.path.exists(p):
        raise RuntimeError(f"{p} not found: build first (meson compile -C build) or set {env}")
    return p


class Reference:
    """Runs fesd_py_reference and parses its records."""

    def __init__(self, exe):
        self.exe = exe

    def __call__(self, *args):
        out = subprocess.run([self.exe] + [str(a) for a in args], check=True, capture_output=True, text=True).stdout
        rec = {"t": [], "x": [], "event": [], "sizes": {}, "offsets": {}}
        for line in out.splitlines():
            name, *vals = line.split()
            if name == "size":
                rec["sizes"][vals[0]] = int(vals[1])
            elif name == "offset":
                rec["offsets"][vals[0]] = int(vals[1])
            elif name == "event":
                t, sys, kind, nb = float(vals[0]), int(vals[1]), int(vals[2]), int(vals[3])
                before = tuple(int(v) for v in vals[4:4 + nb])
                na = int(vals[4 + nb])
                after = tuple(int(v) for v in vals[5 + nb:5 + nb + na])
                rec["event"].append((t, sys, kind, before, after))
            elif name in ("t", "x"):
                rec[name].append([float(v) for v in vals])
            elif name in ("status",):
                rec[name] = int(vals[0])
            else:
                rec[name] = [float(v) for v in vals]
        rec["t"] = np.array(rec["t"]).reshape(-1)
        rec["x"] = np.array(rec["x"])
        return rec


@pytest.fixture(scope="session")
def reference():
    return Reference(_path("FESD_PY_REFERENCE", os.path.join(ROOT, "build", "python", "fesd_py_reference")))


@pytest.fixture(scope="session")
def readme_path():
    return _path("FESD_README", os.path.join(ROOT, "README.md"))
