#!/usr/bin/env python3
"""fesd-run's argument checks (examples/fesd_run.c): every bad value gives exit status 2
and a message naming it, write errors give exit status 1 and a message, and good runs
print the exact figures of the built-in problems.

Usage: test_cli.py PATH/TO/fesd-run"""
import os
import re
import subprocess
import sys
import tempfile

exe = sys.argv[1]
fails = 0


def run(args, stdout=subprocess.PIPE):
    p = subprocess.run([exe] + args, stdout=stdout, stderr=subprocess.PIPE, text=True, timeout=120)
    return p.returncode, p.stdout or "", p.stderr


def check(ok, what):
    global fails
    if not ok:
        fails += 1
        print("FAIL: " + what)


# (arguments, exit status, text the message must contain)
BAD = [
    (["--problem", "sign-a", "--nsim", "0"], 2, "--nsim"),
    (["--problem", "sign-a", "--nsim", "-5"], 2, "--nsim"),
    (["--problem", "sign-a", "--nsim", "2147483648"], 2, "--nsim"),
    (["--problem", "sign-a", "--nsim", "10abc"], 2, "--nsim"),
    (["--problem", "sign-a", "--nsim", ""], 2, "--nsim"),
    (["--problem", "sign-a", "--nsim", "1e3"], 2, "--nsim"),
    (["--problem", "sign-a", "--stages", "0"], 2, "--stages"),
    (["--problem", "sign-a", "--stages", "-2"], 2, "--stages"),
    (["--problem", "sign-a", "--stages", "13"], 2, "--stages"),
    (["--problem", "sign-a", "--nfe", "1"], 2, "--nfe"),
    (["--problem", "sign-a", "--nfe", "-1", "--method", "std"], 2, "--nfe"),
    (["--problem", "sign-a", "--nfe", "1001"], 2, "--nfe"),
    (["--problem", "sign-a", "--T", "nan"], 2, "--T"),
    (["--problem", "sign-a", "--T", "inf"], 2, "--T"),
    (["--problem", "sign-a", "--T", "-inf"], 2, "--T"),
    (["--problem", "sign-a", "--T", "1e999"], 2, "--T"),
    (["--problem", "sign-a", "--T", "0"], 2, "--T"),
    (["--problem", "sign-a", "--T", "-1"], 2, "--T"),
    (["--problem", "sign-a", "--T", "1.5s"], 2, "--T"),
    (["--problem", "oscillator", "--x0", "1,2,3"], 2, "--x0"),
    (["--problem", "oscillator", "--x0", "1"], 2, "--x0"),
    (["--problem", "oscillator", "--x0", "nan,0"], 2, "--x0"),
    (["--problem", "oscillator", "--x0", "0,inf"], 2, "--x0"),
    (["--problem", "oscillator", "--x0", "1,,2"], 2, "--x0"),
    (["--problem", "oscillator", "--x0", "1,2,"], 2, "--x0"),
    (["--problem", "oscillator", "--x0", "1;2"], 2, "--x0"),
    (["--problem", "oscillator", "--x0", "1,2x"], 2, "--x0"),
    (["--problem", "nope"], 2, "unknown problem"),
    ([], 2, "--problem"),
    (["--problem", "sign-a", "--method", "rk"], 2, "method"),
    (["--problem", "sign-a", "--family", "rk"], 2, "family"),
    (["--problem", "sign-a", "--bogus", "1"], 2, "--bogus"),
    (["--problem", "sign-a", "stray"], 2, "stray"),
    (["--problem", "sign-a", "--nsim"], 2, "--nsim"),
    (["--problem", "sign-a", "--family", "lobatto3a", "--stages", "1"], 2, "FESD_ERR_UNSUPPORTED_TABLEAU"),
    (["--problem", "sign-a", "--csv", "/nonexistent-dir/x.csv"], 1, "/nonexistent-dir/x.csv"),
    (["--problem", "sign-a", "--events", "/nonexistent-dir/e.csv"], 1, "/nonexistent-dir/e.csv"),
    (["--problem", "sign-a", "--rtol", "0"], 2, "--rtol"),
    (["--problem", "sign-a", "--rtol", "1"], 2, "--rtol"),
    (["--problem", "sign-a", "--rtol", "nan"], 2, "--rtol"),
    (["--problem", "sign-a", "--atol", "-1e-9"], 2, "--atol"),
    (["--problem", "sign-a", "--max-step", "-1"], 2, "--max-step"),
    (["--problem", "sign-a", "--tout", "0.5,0.2"], 2, "--tout"),
    (["--problem", "sign-a", "--tout", "0.5,,0.7"], 2, "--tout"),
    (["--problem", "sign-a", "--tout", "0:1:1"], 2, "--tout"),
    (["--problem", "sign-a", "--tout", "1:0:5"], 2, "--tout"),
    (["--problem", "sign-a", "--tout", "0:1:2.5"], 2, "--tout"),
    (["--problem", "sign-a", "--tout", "0,7"], 2, "--tout"),
    (["--problem", "sign-a", "--tout", "-1,0.5"], 2, "--tout"),
]
if os.path.exists("/dev/full"):
    BAD.append((["--problem", "sign-a", "--csv", "/dev/full"], 1, "/dev/full"))

for args, code, text in BAD:
    rc, out, err = run(args)
    check(rc == code and text in err, "%s: exit %d (expected %d), message %r" % (args, rc, code, err.strip()))
    check(code != 2 or not out, "%s: printed results %r" % (args, out[:80]))  # arguments: nothing runs
n_bad = len(BAD)

# the standard output itself cannot be written
n_full = 0
if os.path.exists("/dev/full"):
    with open("/dev/full", "w") as full:
        rc, _, err = run(["--problem", "sign-a"], stdout=full)
    check(rc == 1 and "standard output" in err, "stdout on /dev/full: exit %d, message %r" % (rc, err.strip()))
    n_full = 1

# good runs: the oscillator (exact solution), its CSV, sign-c's sliding exit, std with N_FE = 1
with tempfile.TemporaryDirectory() as d:
    csv = os.path.join(d, "traj.csv")
    rc, out, err = run(["--problem", "oscillator", "--stages", "3", "--nsim", "40", "--csv", csv])
    m = re.search(r"error \|x\(T\) - exact\|_inf = (\S+)", out)
    xT = re.search(r"x\(T\) = (\S+) (\S+)", out)
    check(rc == 0 and not err and m and float(m.group(1)) < 1e-6,
          "oscillator: exit %d, error line %r, stderr %r" % (rc, m and m.group(0), err))
    rows = open(csv).read().splitlines() if os.path.exists(csv) else []
    check(len(rows) == 1 + 2 * 40 + 1 and rows[0] == "t,x1,x2,h,active",
          "oscillator CSV: %d lines, header %r" % (len(rows), rows[:1]))
    if rows and xT:
        last = rows[-1].split(",")
        check(abs(float(last[1]) - float(xT.group(1))) < 1e-15 and abs(float(last[2]) - float(xT.group(2))) < 1e-15,
              "CSV end state %s != printed x(T) %s" % (last, xT.groups()))
        check(all(re.fullmatch(r"[0-9;]+", r.split(",")[-1]) for r in rows[1:-1]),
              "CSV active column: %r" % rows[1].split(",")[-1])
rc, out, err = run(["--problem", "sign-c", "--nsim", "20"])
check(rc == 0 and "sliding-exit  modes {0,1} -> {0}" in out and "t = 1.000000000000000" in out,
      "sign-c: exit %d, events %r" % (rc, [l for l in out.splitlines() if l.startswith("event")]))
rc, out, err = run(["--problem", "oscillator", "--x0", " 0.5,-0", "--T", "0.25", "--method", "std", "--nfe", "1"])
check(rc == 0 and "x(T) = " in out and "T=0.25" in out, "oscillator from --x0 with --T: exit %d, %r" % (rc, err))

# --help: usage on the standard output, exit 0
rc, out, err = run(["--help"])
check(rc == 0 and out.startswith("usage: fesd-run") and "--rtol" in out and not err, "--help: exit %d, %r" % (rc, out[:60]))

# error-controlled run: output times, CSV of the trajectory and of the events (oscillator:
# x1 = exp(-1) cos(pi t) before the crossing at t = 1 ... exact solution in C; here the
# crossing time and the printed error)
with tempfile.TemporaryDirectory() as d:
    csv, evf = os.path.join(d, "traj.csv"), os.path.join(d, "ev.csv")
    rc, out, err = run(["--problem", "oscillator", "--stages", "3", "--rtol", "1e-9", "--tout", "0:1.5:7",
                        "--csv", csv, "--events", evf, "--quiet"])
    m = re.search(r"error \|x\(T\) - exact\|_inf = (\S+)", out)
    check(rc == 0 and m and float(m.group(1)) < 1e-7, "adaptive oscillator: exit %d, %r, %r" % (rc, m and m.group(0), err))
    rows = [r.split(",") for r in open(csv).read().splitlines()] if os.path.exists(csv) else []
    check(len(rows) == 8 and rows[0] == ["t", "x1", "x2"] and
          all(abs(float(rows[1 + k][0]) - 0.25 * k) < 1e-15 for k in range(7)),
          "adaptive CSV: %d rows, %r" % (len(rows), rows[:2]))
    # the oscillator's exact solution (src/problems/problems.c), t <= 1: exp(t - 1) (cos, sin)(W t)
    import math
    W = 2 * math.pi
    worst = max(abs(float(rows[1 + k][1]) - math.exp(0.25 * k - 1) * math.cos(W * 0.25 * k)) for k in range(5)) \
        if len(rows) == 8 else 1
    check(worst < 1e-7, "adaptive CSV: x1 off by %.1e at the output times before the crossing" % worst)
    ev = [r.split(",") for r in open(evf).read().splitlines()] if os.path.exists(evf) else []
    check(len(ev) == 2 and ev[0] == ["t", "subsystem", "kind", "before", "after"] and ev[1][2] == "crossing" and
          abs(float(ev[1][0]) - 1.0) < 1e-7, "events CSV: %r" % ev)
# fixed steps with an events file: sign-c's exit
with tempfile.TemporaryDirectory() as d:
    evf = os.path.join(d, "ev.csv")
    rc, out, err = run(["--problem", "sign-c", "--nsim", "20", "--events", evf, "--quiet"])
    ev = open(evf).read().splitlines() if os.path.exists(evf) else []
    check(rc == 0 and len(ev) == 2 and ev[1].split(",")[1:] == ["0", "sliding-exit", "0;1", "0"] and abs(float(ev[1].split(",")[0]) - 1) < 1e-12, "sign-c events CSV: %r" % ev)

print("fesd-run: %d bad invocations refused with a message (exit 2 for arguments, 1 for output files), "
      "%d unwritable standard output, 6 good runs checked (fixed and error-controlled, CSV of states and events)" % (n_bad, n_full))
print("%d failures" % fails)
sys.exit(1 if fails else 0)
