"""Reference problems of the paper in Python (the same models as src/problems/problems.c),
with their exact solutions: for examples, tests and benchmarks."""
import math

import numpy as np

from .model import Model, Subsystem

W = 2.0 * math.pi


def oscillator(jacobians=True):
    """Paper Sec. 4.4: x' = A1 x outside the unit circle (mode 0, c > 0), A2 x inside; from
    x0 = (e^-1, 0) it crosses the circle at t = 1. Exact solution: oscillator_exact."""
    def fields(t, x, u):
        a, b = x[0], x[1]
        return np.array([[a + W * b, -W * a + b], [a - W * b, W * a + b]])

    def fields_jac(t, x, u):
        return np.array([[[1.0, W], [-W, 1.0]], [[1.0, -W], [W, 1.0]]])

    def switch(t, x, u):
        return np.array([x[0] * x[0] + x[1] * x[1] - 1.0])

    def switch_jac(t, x, u):
        return np.array([[2 * x[0], 2 * x[1]]])

    sub = Subsystem(2, fields=fields, switch=switch, fields_jac=fields_jac if jacobians else None,
                    switch_jac=switch_jac if jacobians else None)
    return Model(2, [sub])


OSCILLATOR_X0 = np.array([math.exp(-1.0), 0.0])


def oscillator_exact(t):
    a = math.exp(t - 1.0)
    if t <= 1.0:
        return np.array([a * math.cos(W * t), a * math.sin(W * t)])
    return np.array([a * math.cos(W * (t - 1.0)), -a * math.sin(W * (t - 1.0))])


def sign_c():
    """x' in -sign(x) + tau, tau' = 1 (time as the state x[1]), x0 = (0, 0): slides on x = 0
    until t = 1, then x = (t-1)^2/2. Exact: sign_c_exact."""
    def fields(t, x, u):
        return np.array([[-1.0 + x[1], 1.0], [1.0 + x[1], 1.0]])

    def fields_jac(t, x, u):
        J = np.array([[0.0, 1.0], [0.0, 0.0]])
        return np.array([J, J])

    sub = Subsystem(2, fields=fields, switch=lambda t, x, u: x[:1], fields_jac=fields_jac,
                    switch_jac=lambda t, x, u: np.array([[1.0, 0.0]]))
    return Model(2, [sub])


def sign_c_exact(t):
    return np.array([0.0 if t <= 1 else 0.5 * (t - 1) ** 2, t])


def ocp_dynamics():
    """Paper Sec. 5: q' = -sign(c(q)) + v, v' = u with two subsystems (c1 = q1 + 0.15 q2^2,
    c2 = -0.05 q1^3 + q2), nx = 4, nu = 2; x0 = (2pi/3, pi/3, 0, 0), u = 0: sliding on c2 = 0 from
    t1 (ocp_t1()), at the origin from 2pi/3."""
    def f0(t, x, u):
        return np.array([[-1.0 + x[2], x[3], u[0], u[1]], [1.0 + x[2], x[3], u[0], u[1]]])

    def f0_jac(t, x, u):
        J = np.zeros((4, 4))
        J[0, 2] = J[1, 3] = 1.0
        Ju = np.zeros((4, 2))
        Ju[2, 0] = Ju[3, 1] = 1.0
        return np.array([J, J]), np.array([Ju, Ju])

    def f1(t, x, u):
        return np.array([[0.0, -1.0, 0.0, 0.0], [0.0, 1.0, 0.0, 0.0]])

    def f1_jac(t, x, u):
        return np.zeros((2, 4, 4)), np.zeros((2, 4, 2))

    s0 = Subsystem(2, fields=f0, switch=lambda t, x, u: np.array([x[0] + 0.15 * x[1] ** 2]), fields_jac=f0_jac,
                   switch_jac=lambda t, x, u: (np.array([[1.0, 0.3 * x[1], 0.0, 0.0]]), np.zeros((1, 2))))
    s1 = Subsystem(2, fields=f1, switch=lambda t, x, u: np.array([-0.05 * x[0] ** 3 + x[1]]), fields_jac=f1_jac,
                   switch_jac=lambda t, x, u: (np.array([[-0.15 * x[0] ** 2, 1.0, 0.0, 0.0]]), np.zeros((1, 2))))
    return Model(4, [s0, s1], nu=2)


OCP_X0 = np.array([2 * math.pi / 3, math.pi / 3, 0.0, 0.0])


def ocp_t1():
    """Time at which ocp-dynamics reaches c2 = 0 (bisection, as problems.c)."""
    t2, a, b = 2 * math.pi / 3, 0.0, 1.5
    for _ in range(200):
        m = 0.5 * (a + b)
        q1 = t2 - m
        if -0.05 * q1 ** 3 + (t2 / 2 - m) > 0:
            a = m
        else:
            b = m
    return 0.5 * (a + b)


def ocp_exact(t):
    t2, t1 = 2 * math.pi / 3, ocp_t1()
    q1 = t2 - t if t < t2 else 0.0
    return np.array([q1, math.pi / 3 - t if t < t1 else 0.05 * q1 ** 3, 0.0, 0.0])


OCP_STEP_EQ_TARGET = np.array([-math.pi / 6, -math.pi / 4])


def ocp_step_eq(n_ctrl=6, jacobians=True, **kwargs):
    """Paper Sec. 6.3 (src/problems/ocp_step_eq.c) as a fesd.OCP on ocp_dynamics(): x0 = OCP_X0,
    T = 4, |v| <= 2, |u| <= 10, cost int u'u + v'v dt (lagrange_lsq r = (u, v)) + 1e3 ||q(4) -
    (-pi/6, -pi/4)||_1. jacobians=False: the OCP functions without Jacobians (central
    differences in the wrapper). kwargs: fesd.OCP's (stages, n_fe, method, OCP settings, ...).
    Start it from ocp_step_eq_guess(n_ctrl) as the C tests do."""
    from .ocp import OCP
    qf = OCP_STEP_EQ_TARGET
    Jl_x, Jl_u = np.zeros((4, 4)), np.zeros((4, 2))
    Jl_x[2, 2] = Jl_x[3, 3] = Jl_u[0, 0] = Jl_u[1, 1] = 1.0
    J1 = np.zeros((2, 4))
    J1[0, 0] = J1[1, 1] = 1.0
    inf = math.inf
    return OCP(ocp_dynamics(), n_ctrl, 0.0, 4.0, OCP_X0, x_lb=[-inf, -inf, -2, -2], x_ub=[inf, inf, 2, 2],
               u_lb=-10.0, u_ub=10.0,
               lagrange_lsq=lambda t, x, u: np.array([u[0], u[1], x[2], x[3]]),
               lagrange_lsq_jac=(lambda t, x, u: (Jl_x, Jl_u)) if jacobians else None,
               l1=lambda x: np.array([x[0] - qf[0], x[1] - qf[1]]), l1_jac=(lambda x: J1) if jacobians else None,
               l1_weight=[1e3, 1e3], **kwargs)


def ocp_step_eq_guess(n_ctrl=6):
    """The C tests' control guess (fesd_ocp_step_eq_guess): -1 on the first half, 0 after."""
    return np.array([[-1.0, -1.0] if 2 * k < n_ctrl else [0.0, 0.0] for k in range(n_ctrl)])


def stewart_anitescu():
    """Paper Sec. 5.3: x' in 2 - sign(x) with the running cost q' = x^2 (states x, q)."""
    sub = Subsystem(2, fields=lambda t, x, u: np.array([[1.0, x[0] ** 2], [3.0, x[0] ** 2]]),
                    switch=lambda t, x, u: x[:1],
                    fields_jac=lambda t, x, u: np.array([[[0.0, 0.0], [2 * x[0], 0.0]]] * 2),
                    switch_jac=lambda t, x, u: np.array([[1.0, 0.0]]))
    return Model(2, [sub])


def stewart_anitescu_exact(x0):
    """V(x0) = int_0^2 x^2 dt + (x(2) - 5/3)^2 and dV/dx0 (closed form, as problems.c)."""
    if x0 >= 0:
        V = ((x0 + 2) ** 3 - x0 ** 3) / 3 + (x0 + 1.0 / 3) ** 2
        d = (x0 + 2) ** 2 - x0 ** 2 + 2 * (x0 + 1.0 / 3)
    else:
        a, b = 2 + x0 / 3, (1 + x0) / 3
        V = -x0 ** 3 / 9 + a ** 3 / 3 + b * b
        d = -x0 ** 2 / 3 + a * a / 3 + 2 * b / 3
    return V, d


def friction():
    """The README's quick start: x'' = -x - sign(x'), one switching function c = v."""
    sub = Subsystem(2, fields=lambda t, x, u: np.array([[x[1], -x[0] - 1.0], [x[1], -x[0] + 1.0]]),
                    switch=lambda t, x, u: x[1])
    return Model(2, [sub])
