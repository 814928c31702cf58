"""Dense output over a whole integration: the collocation polynomial of every element.

The library evaluates the polynomial of its last accepted step (fesd_dense_output); a
polynomial of degree s is fixed by s + 1 values, so after each step the driver samples every
element at s + 1 Chebyshev-Lobatto points and DenseSolution interpolates them (barycentric
Lagrange form): the same polynomial, to round-off.
"""
import numpy as np


def sample_nodes(s):
    """s + 1 points in [0, 1] (Chebyshev-Lobatto), ends included."""
    j = np.arange(s + 1)
    return 0.5 * (1.0 - np.cos(np.pi * j / s)) if s > 0 else np.zeros(1)


class DenseSolution:
    """Callable sol(t) -> x (nx,) for a float, (nx, len(t)) for an array (like scipy's
    OdeSolution). t outside [t_min, t_max] raises ValueError. Built by the drivers of
    fesd.solve_ivp; .ts: element boundaries."""

    def __init__(self, nodes, nx):
        self.nodes = np.asarray(nodes, dtype=float)
        m = self.nodes.size
        w = np.ones(m)
        for j in range(m):
            for k in range(m):
                if k != j:
                    w[j] /= self.nodes[j] - self.nodes[k]
        self.weights = w
        self.nx = nx
        self._t0, self._h, self._vals = [], [], []

    def add_element(self, t0, h, values):
        """values: (len(nodes), nx) samples of the element's polynomial at t0 + nodes * h."""
        self._t0.append(float(t0))
        self._h.append(float(h))
        self._vals.append(np.asarray(values, dtype=float))

    def finalize(self):
        self.t0 = np.asarray(self._t0)
        self.h = np.asarray(self._h)
        self.vals = np.asarray(self._vals).reshape(len(self._t0), self.nodes.size, self.nx)
        self.ts = np.append(self.t0, self.t0[-1] + self.h[-1]) if self.t0.size else np.zeros(0)
        return self

    @property
    def t_min(self):
        return self.ts[0]

    @property
    def t_max(self):
        return self.ts[-1]

    def __call__(self, t):
        t_arr = np.asarray(t, dtype=float)
        tt = np.atleast_1d(t_arr)
        span = self.t_max - self.t_min
        tol = 1e-12 * max(1.0, abs(self.t_min), abs(self.t_max))
        if np.any(tt < self.t_min - tol) or np.any(tt > self.t_max + tol) or span < 0:
            raise ValueError(f"t outside the integration interval [{self.t_min}, {self.t_max}]")
        e = np.clip(np.searchsorted(self.t0, tt, side="right") - 1, 0, self.t0.size - 1)
        tau = np.clip((tt - self.t0[e]) / np.where(self.h[e] > 0, self.h[e], 1.0), 0.0, 1.0)
        diff = tau[:, None] - self.nodes[None, :]
        exact = diff == 0.0
        diff[exact] = 1.0
        q = self.weights[None, :] / diff
        q[exact.any(axis=1)] = exact[exact.any(axis=1)].astype(float)
        q /= q.sum(axis=1, keepdims=True)
        out = np.einsum("pj,pjr->rp", q, self.vals[e])
        return out[:, 0] if t_arr.ndim == 0 else out
