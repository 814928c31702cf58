#!/usr/bin/env python3
"""Summary of the bench CSVs (tools/bench.sh) as Markdown tables: headline FESD against
standard, performance targets, integration orders, sliding exits, sensitivities,
Stewart-Anitescu and the cost anatomy. Usage: tools/bench_summary.py [RESULTS_DIR]"""
import csv
import math
import os
import sys

D = sys.argv[1] if len(sys.argv) > 1 else "bench/results"


def rows(name):
    path = os.path.join(D, name)
    if not os.path.exists(path):
        return []
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def num(v):
    try:
        return float(v)
    except (TypeError, ValueError):
        return math.nan


def e(v):
    x = num(v)
    return "—" if math.isnan(x) else f"{x:.1e}"


def f(v, d=2):
    x = num(v)
    return "—" if math.isnan(x) else f"{x:.{d}f}"


def table(head, body):
    print("| " + " | ".join(head) + " |")
    print("|" + "---|" * len(head))
    for r in body:
        print("| " + " | ".join(r) + " |")
    print()


def anatomy_row(prob, method, s=None, nsim=None, backend="auto"):
    for r in rows("anatomy.csv"):
        if (r["problem"], r["method"], r["backend"]) == (prob, method, backend) and \
                (s is None or (r["s"], r["nsim"]) == (s, nsim)):
            return r
    return None


print("### FESD against standard time-stepping (Radau IIA s = 1..5, N_sim doubling)\n")
body = []
for r in rows("pareto_summary.csv"):
    if r["variant"] != "fesd":
        continue
    p = r["problem"]
    ast = anatomy_row(p, "standard")  # the same configuration for both methods
    af = anatomy_row(p, "fesd", ast["s"], ast["nsim"]) if ast else None
    step = "—"
    if af and ast:
        step = (f"{f(af['us_per_step'], 1)} / {f(ast['us_per_step'], 1)} "
                f"(s={af['s']}, N={af['nsim']})")
    metric = "switch times" if p == "ocp-dynamics" else "x(T)"
    body.append([f"{p} ({metric})", f"{e(r['fesd_best_err'])} / {e(r['std_best_err'])}", step,
                 f"{e(r['ratio_equal_cpu'])} ({e(r['ratio_min'])} .. {e(r['ratio_max'])})",
                 f"{f(r['fesd_ms_to_std_best'], 3)} ms vs {f(r['std_best_ms'], 3)} ms "
                 f"(x{f(r['speedup'], 1)})"])
table(["problem (error of)", "best error FESD / standard", "µs per step FESD / standard",
       "standard / FESD error at equal CPU (range)", "time to the standard's best error: FESD vs standard"],
      body)
for r in rows("pareto_summary.csv"):
    if r["variant"] == "fesd-exit0":
        print(f"{r['problem']} with the paper's exit formulation (exit_rows = 0): standard / FESD error "
              f"at equal CPU {e(r['ratio_equal_cpu'])}; best error {e(r['fesd_best_err'])}.\n")

print("### Performance targets (measured, not asserted)\n")
body = []
for r in rows("targets.csv"):
    cfg = f"Radau s={r['s'].split('.')[0]}, N_sim={r['nsim'].split('.')[0]}, error {e(r['err'])}"
    body.append([f"{r['problem']}: error <= {r['target_err']}", f"{f(r['cpu_ms'], 3)} ms ({cfg})",
                 f"<= {r['target_ms']} ms", f(r["ratio_to_target"])])
tgt = [r for r in rows("targets.csv") if r["problem"] == "oscillator"]
a = anatomy_row("oscillator", "fesd", *((tgt[0]["s"], tgt[0]["nsim"]) if tgt else (None, None)))
a = a or anatomy_row("oscillator", "fesd")
if a:
    body.append([f"time per Newton iteration / one LU + solve (oscillator s={a['s']}, N={a['nsim']}, n={a['n']})",
                 f"{f(a['us_per_newton'], 1)} µs / {f(a['us_lapack_lu'], 1)} µs = {f(a['ratio_newton_to_lu'])}",
                 "<= 2", f(num(a["ratio_newton_to_lu"]) / 2)])
    body.append(["same, against the library's own factorization + solve (backend "
                 f"{a['backend']}: {f(a['us_lib_factor_solve'], 1)} µs)",
                 f(num(a["us_per_newton"]) / num(a["us_lib_factor_solve"])), "—", "—"])
table(["target", "measured", "target", "measured / target"], body)

print("### Integration order, oscillator, N_FE = 2 (fitted slopes)\n")
table(["tableau", "p", "FESD", "FESD switch time", "standard"],
      [[f"{r['family']} s={r['s']}", r["p"], f(r["slope_fesd"]), f(r["slope_ts_fesd"]), f(r["slope_std"])]
       for r in rows("order_slopes.csv")])

print("### Sliding exits (max over N_sim; fitted orders)\n")
table(["problem", "variant", "s", "state error (order)", "exit-time error (order)"],
      [[r["problem"], r["variant"], r["s"], f"{e(r['max_err_state'])} ({f(r['order_state'])})",
        f"{e(r['max_err_exit'])} ({f(r['order_exit'])})"] for r in rows("sliding_exit_orders.csv")])

print("### Sensitivities: overhead of settings.sensitivities = 1\n")
table(["problem", "method", "s", "N_sim", "CPU ms off → on", "ratio"],
      [[r["problem"], r["method"], r["s"], r["nsim"], f"{f(r['cpu_ms_off'], 3)} → {f(r['cpu_ms_on'], 3)}",
        f(r["ratio"])] for r in rows("sensitivity_overhead.csv")])

print("### Stewart-Anitescu (Gauss-Legendre s = 2, N_FE = 25, one step)\n")
table(["method", "max error of V", "max error of dV/dx0", "shooting reaches x0*", "ms per V + gradient"],
      [[r["method"], e(r["max_err_V"]), e(r["max_err_dV"]), f"{r['shoot_ok']} of {r['shoot_starts']}",
        f(r["cpu_ms_value_gradient"], 3)] for r in rows("sa_summary.csv")])

print("### Cost anatomy (shares of the wall time of an integration)\n")
table(["problem", "method", "s", "N", "backend", "n", "µs/step", "Newton/step", "solves/step", "eval", "linsolve",
       "solver rest", "rows", "outside", "model", "µs/Newton", "LU µs", "Newton/LU"],
      [[r["problem"], r["method"], r["s"], r["nsim"], r["backend"], r["n"], f(r["us_per_step"], 1),
        f(r["newton_per_step"]), f(r["solves_per_step"]), f(r["share_eval"]), f(r["share_linsolve"]), f(r["share_solver_other"]),
        f(r["share_set_rows"]), f(r["share_outside"]), f(r["share_model"]), f(r["us_per_newton"], 1),
        f(r["us_lapack_lu"], 1), f(r["ratio_newton_to_lu"])] for r in rows("anatomy.csv")])
