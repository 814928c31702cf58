#!/usr/bin/env python3
"""Integration order on the oscillator (paper Fig. integrator_order): error of x(pi/2) against
the step length for Radau IIA s = 1..4, FESD against standard time-stepping (N_FE = 2, fixed
steps). FESD keeps the order 2s - 1 across the crossing at t = 1; the standard method drops to
about 1. (s = 1, implicit Euler, has a large error constant, |lambda| h ~ 2 pi h: no
point of this grid is in its asymptotic range and its slope is not fitted.) Writes integration_order.png (to the directory given, default the current one) and
prints the fitted slopes.

    PYTHONPATH=python python3 python/examples/integration_order.py [OUTDIR] [--quick]

--quick: s = 2..4 and N_sim up to 160 (the test's run).
"""
import math
import os
import sys

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import fesd  # noqa: E402
from fesd import problems as P  # noqa: E402

T = math.pi / 2
NSIM = [10, 20, 40, 80, 160, 320, 640]


def error(method, s, nsim):
    res = fesd.solve_ivp(P.oscillator(), (0, T), P.OSCILLATOR_X0, h=T / nsim, method=method, stages=s, n_fe=2)
    return np.abs(res.y[:, -1] - P.oscillator_exact(T)).max()


def main(outdir=".", quick=False):
    nsim = NSIM[:5] if quick else NSIM
    h = T / np.array(nsim)
    fig, ax = plt.subplots(figsize=(7, 5))
    print(f"{'method':9s} {'s':>2s} {'slope':>6s}  errors")
    for s in range(2 if quick else 1, 5):
        for method, style in (("fesd", "o-"), ("standard", "x--")):
            err = np.array([error(method, s, n) for n in nsim])
            ok = (err > 1e-13) & (err < 0.5)  # between round-off and the pre-asymptotic range
            slope = np.polyfit(np.log(h[ok]), np.log(err[ok]), 1)[0] if ok.sum() >= 2 else float("nan")
            print(f"{method:9s} {s:2d} {slope:6.2f}  " + " ".join(f"{e:.1e}" for e in err))
            ax.loglog(h, np.maximum(err, 1e-16), style, color=f"C{s - 1}", ms=4,
                      label=f"{method} Radau s={s} (slope {slope:.2f})")
    ax.set_xlabel("step length h")
    ax.set_ylabel("error of x(pi/2)")
    ax.set_title("oscillator, Radau IIA, N_FE = 2")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7)
    path = os.path.join(outdir, "integration_order.png")
    fig.savefig(path, dpi=120)
    print("wrote", path)
    return path


if __name__ == "__main__":
    main(*[a for a in sys.argv[1:2] if a != "--quick"], quick="--quick" in sys.argv)
