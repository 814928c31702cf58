#!/usr/bin/env python3
"""ocp_step_eq (paper Sec. 6.3) from Python: fesd.OCP on the "ocp-dynamics" model, x0 = (2pi/3,
pi/3, 0, 0), T = 4, N_ctrl = 6, |v| <= 2, |u| <= 10, cost int u'u + v'v dt + 1e3 ||q(4) - (-pi/6,
-pi/4)||_1 (fesd.problems.ocp_step_eq), solved with FESD (Radau IIA s = 2) and with the standard
time-stepping method on the same grid. Prints the solver's summary, the controls, the switches
per interval and the terminal error E(T) = ||q(T) - q_final|| of the optimal controls
re-simulated with a fine FESD integration (Radau IIA s = 4, nsub steps per interval, as
fesd_ocp_step_eq_resimulate in C). With OUTDIR, writes OUTDIR/ocp_step_eq.png (matplotlib).

    PYTHONPATH=python python3 python/examples/ocp_step_eq.py [OUTDIR] [--nfe N] [--quick]

--quick: nsub = 10 (the test's run); default 40.
"""
import math
import os
import sys

import numpy as np

import fesd
from fesd import problems as P


def resimulate(u, n_ctrl=6, T=4.0, nsub=40):
    """q(T) of ocp_dynamics with the piecewise constant controls u (n_ctrl, 2)."""
    it = fesd.Integrator(P.ocp_dynamics(), stages=4, n_fe=2)
    it.set_state(0.0, P.OCP_X0, u[0])
    for k in range(n_ctrl):
        for _ in range(nsub):
            it.step(T / n_ctrl / nsub, u[k])
    return it.x


def solve(method, n_fe):
    ocp = P.ocp_step_eq(method=method, stages=2, n_fe=n_fe)
    return ocp.solve(u_guess=P.ocp_step_eq_guess(6))


def plot(results, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from fesd.plot import KIND_STYLE
    fig, axs = plt.subplots(1, 2, figsize=(11, 4))
    for name, res in results.items():
        ts = np.concatenate([iv.t for iv in res.intervals])
        xs = np.concatenate([iv.x for iv in res.intervals])
        ls = "-" if name == "fesd" else ":"
        axs[0].plot(ts, xs[:, 0], ls, color="tab:blue", label=f"q1 ({name})")
        axs[0].plot(ts, xs[:, 1], ls, color="tab:orange", label=f"q2 ({name})")
        axs[1].step(res.t, np.append(res.u[:, 0], res.u[-1, 0]), ls, where="post", color="tab:blue",
                    label=f"u1 ({name})")
        axs[1].step(res.t, np.append(res.u[:, 1], res.u[-1, 1]), ls, where="post", color="tab:orange",
                    label=f"u2 ({name})")
    for iv in results["fesd"].intervals:
        for e in iv.events:
            color, style = KIND_STYLE.get(e.kind, ("gray", "-"))
            axs[0].axvline(e.t, color=color, ls=style, lw=0.8)
    for q in P.OCP_STEP_EQ_TARGET:
        axs[0].axhline(q, color="gray", lw=0.5)
    axs[0].set_xlabel("t")
    axs[0].set_title("states at the element boundaries (lines: FESD switches)")
    axs[1].set_xlabel("t")
    axs[1].set_title("optimal controls")
    for ax in axs:
        ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=110)


def main(argv):
    args = [a for a in argv[1:]]
    quick = "--quick" in args
    n_fe = 2
    if "--nfe" in args:
        n_fe = int(args[args.index("--nfe") + 1])
        del args[args.index("--nfe"):args.index("--nfe") + 2]
    outdir = next((a for a in args if not a.startswith("--")), None)
    nsub = 10 if quick else 40
    results = {}
    for method in ("fesd", "standard"):
        res = solve(method, n_fe)
        results[method] = res
        print(f"== {method}, Radau IIA s = 2, N_FE = {n_fe}, N_ctrl = 6")
        print(res.summary())
        print("controls u_k:")
        for k, uk in enumerate(res.u):
            print(f"  k = {k}: ({uk[0]: .8f}, {uk[1]: .8f})")
        for iv in res.intervals:
            if iv.events:
                print(f"  interval {iv.k}: " + ", ".join(f"{e.kind} of subsystem {e.sys} at t = {e.t:.6f}"
                                                       for e in iv.events))
        xT = resimulate(res.u, nsub=nsub)
        E = math.hypot(*(xT[:2] - P.OCP_STEP_EQ_TARGET))
        print(f"{method} objective {res.objective:.10f} E(T) {E:.3e} status {res.status_name}")
    if outdir:
        os.makedirs(outdir, exist_ok=True)
        path = os.path.join(outdir, "ocp_step_eq.png")
        plot(results, path)
        print("wrote", path)


if __name__ == "__main__":
    main(sys.argv)
