"""Plots of solve_ivp results (matplotlib; pick the backend before importing pyplot, e.g.
MPLBACKEND=Agg for files only).

plot_trajectory: states against t, switches marked, sliding arcs shaded;
plot_elements: element lengths against t (the switch detection moves element boundaries onto
the switches); plot_work_precision: error against cost, one curve per method.
"""
import numpy as np

KIND_STYLE = {"crossing": ("tab:red", "--"), "sliding_entry": ("tab:green", "-."),
              "sliding_exit": ("tab:purple", ":")}


def _axes(ax):
    if ax is not None:
        return ax.figure, ax
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(7, 4))
    return fig, ax


def sliding_intervals(switch_events, t_end):
    """[(t_start, t_end, sys)] where a subsystem has more than one active mode (sliding), from
    the switch events (the active set before a subsystem's first event is its `before`)."""
    out, start = [], {}
    first = {}
    for ev in switch_events:
        first.setdefault(ev.sys, ev)
    for sys, ev in first.items():
        if len(ev.before) > 1:
            start[sys] = -np.inf
    for ev in switch_events:
        sliding = len(ev.after) > 1
        if sliding and ev.sys not in start:
            start[ev.sys] = ev.t
        elif not sliding and ev.sys in start:
            out.append((start.pop(ev.sys), ev.t, ev.sys))
    out += [(t0, t_end, sys) for sys, t0 in start.items()]
    return sorted(out)


def plot_trajectory(res, ax=None, labels=None, states=None, n_dense=400):
    """States of a solve_ivp result against t: the dense output when there is one (points
    marked), switches as vertical lines (colour by kind), sliding arcs shaded."""
    fig, ax = _axes(ax)
    idx = range(res.y.shape[0]) if states is None else states
    t0 = res.t[0]
    t1 = res.t[-1]
    for i in idx:
        lab = labels[i] if labels else f"x{i + 1}"
        if res.get("sol") is not None:
            tt = np.linspace(res.sol.t_min, res.sol.t_max, n_dense)
            line, = ax.plot(tt, res.sol(tt)[i], label=lab)
            ax.plot(res.t, res.y[i], ".", color=line.get_color(), ms=3)
        else:
            ax.plot(res.t, res.y[i], ".-", ms=3, label=lab)
    if res.get("sol") is not None:
        t0 = min(t0, res.sol.t_min)
    seen = set()
    for ev in res.switch_events:
        color, style = KIND_STYLE[ev.kind]
        lab = ev.kind.replace("_", " ") if ev.kind not in seen else None
        seen.add(ev.kind)
        ax.axvline(ev.t, color=color, ls=style, lw=1, label=lab)
    shaded = False
    for a, b, sys in sliding_intervals(res.switch_events, t1):
        ax.axvspan(max(a, t0), b, color="tab:green", alpha=0.12, lw=0, label=None if shaded else "sliding")
        shaded = True
    if res.get("t_events"):
        for k, te in enumerate(res.t_events):
            if len(te):
                ax.plot(te, res.y_events[k][:, idx[0] if states else 0], "kx", label=f"stop condition {k}")
    ax.set_xlabel("t")
    ax.legend(loc="best", fontsize=8)
    return fig, ax


def plot_elements(res, ax=None):
    """Element lengths h_n against their start times (solve_ivp(..., record_elements=True))."""
    if not res.element_t:
        raise ValueError("no element data: call solve_ivp with record_elements=True (fixed steps or steps "
                         "without t_eval)")
    fig, ax = _axes(ax)
    b = np.concatenate([np.asarray(t) for t in res.element_t])
    starts, ends = [], []
    for t in res.element_t:
        starts.extend(t[:-1])
        ends.extend(t[1:])
    starts, h = np.asarray(starts), np.asarray(ends) - np.asarray(starts)
    ax.step(starts, h, where="post", color="tab:blue", label="element length h_n")
    ax.plot(starts, h, ".", color="tab:blue", ms=3)
    for ev in res.switch_events:
        color, style = KIND_STYLE[ev.kind]
        ax.axvline(ev.t, color=color, ls=style, lw=1)
    ax.set_xlabel("t")
    ax.set_ylabel("h_n")
    ax.set_xlim(b.min(), b.max())
    ax.legend(loc="best", fontsize=8)
    return fig, ax


def plot_work_precision(curves, ax=None, xlabel="CPU time [s]", ylabel="error"):
    """curves: {label: (costs, errors)}: error against cost on log-log axes."""
    fig, ax = _axes(ax)
    for label, (cost, err) in curves.items():
        ax.loglog(cost, np.maximum(err, 1e-17), "o-", ms=4, label=label)
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(loc="best", fontsize=8)
    return fig, ax
