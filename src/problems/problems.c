#include "problems/problems.h"

#include <math.h>
#include <string.h>

static const int one_sys_two_modes[1] = {2};
static const int one_switch[1] = {1};
#define PI 3.14159265358979323846
static const double W = 2.0 * PI;

/* ---- oscillator (paper Sec. 4.4): mode 0 = c > 0 (outside): A1 x, mode 1 = c < 0: A2 x ---- */
static int osc_field(int sys, int mode, double t, const double *x, const double *u, double *f, void *user) {
  (void)sys, (void)u, (void)user;
  double s = mode == 0 ? 1.0 : -1.0; /* A1 = [[1, w], [-w, 1]], A2 = [[1, -w], [w, 1]] */
  f[0] = x[0] + s * W * x[1];
  f[1] = -s * W * x[0] + x[1];
  return 0;
}
static int osc_field_jac(int sys, int mode, double t, const double *x, const double *u, double *J, double *Ju,
                         void *user) {
  (void)sys, (void)x, (void)u, (void)Ju, (void)user;
  double s = mode == 0 ? 1.0 : -1.0;
  J[0] = 1;
  J[1] = -s * W;
  J[2] = s * W;
  J[3] = 1;
  return 0;
}
static int osc_sw(int sys, double t, const double *x, const double *u, double *c, void *user) {
  (void)sys, (void)u, (void)user;
  c[0] = x[0] * x[0] + x[1] * x[1] - 1.0;
  return 0;
}
static int osc_sw_jac(int sys, double t, const double *x, const double *u, double *J, double *Ju, void *user) {
  (void)sys, (void)u, (void)Ju, (void)user;
  J[0] = 2 * x[0];
  J[1] = 2 * x[1];
  return 0;
}
int fesd_problem_oscillator_exact(double t, double *x) {
  double a = exp(t - 1.0);
  if (t <= 1.0) {
    x[0] = a * cos(W * t);
    x[1] = a * sin(W * t);
  } else {
    x[0] = a * cos(W * (t - 1.0));
    x[1] = -a * sin(W * (t - 1.0));
  }
  return 0;
}

/* ---- scalar sign examples: c = x, mode 0 = x > 0, mode 1 = x < 0 ---- */
typedef struct {
  double f_pos, f_neg, t_coef, x2_coef;
} scalar_law;
/* f_mode(x, t) = f + t_coef * t + x2_coef * x^2; time enters as state x[1] (x[1]' = 1) */
static const scalar_law law_a = {1, 3, 0, 0};  /* 2 - sign(x) */
static const scalar_law law_b = {-1, 1, 0, 0}; /* -sign(x) */
static const scalar_law law_c = {-1, 1, 1, 0}; /* -sign(x) + t */
static const scalar_law law_d = {1, -1, 0, 0}; /* sign(x) */
static const scalar_law law_nl = {1, 3, 0, 1}; /* 2 - sign(x) + x^2 */

static int scalar_field(int sys, int mode, double t, const double *x, const double *u, double *f, void *user) {
  (void)sys, (void)u;
  const scalar_law *L = user;
  f[0] = (mode == 0 ? L->f_pos : L->f_neg) + L->t_coef * x[1] + L->x2_coef * x[0] * x[0];
  f[1] = 1.0;
  return 0;
}
static int scalar_field_jac(int sys, int mode, double t, const double *x, const double *u, double *J,
                            double *Ju, void *user) {
  (void)sys, (void)mode, (void)u, (void)Ju;
  const scalar_law *L = user;
  J[0] = 2 * L->x2_coef * x[0];
  J[1] = 0;
  J[2] = L->t_coef;
  J[3] = 0;
  return 0;
}
static int scalar_sw(int sys, double t, const double *x, const double *u, double *c, void *user) {
  (void)sys, (void)u, (void)user;
  c[0] = x[0];
  return 0;
}
static int scalar_sw_jac(int sys, double t, const double *x, const double *u, double *J, double *Ju, void *user) {
  (void)sys, (void)x, (void)u, (void)Ju, (void)user;
  J[0] = 1;
  J[1] = 0;
  return 0;
}
static int exact_a(double t, double *x) {
  x[0] = t <= 1.0 / 3 ? -1 + 3 * t : t - 1.0 / 3;
  x[1] = t;
  return 0;
}
static int exact_b(double t, double *x) {
  x[0] = t <= 1 ? 1 - t : 0;
  x[1] = t;
  return 0;
}
static int exact_c(double t, double *x) {
  x[0] = t <= 1 ? 0 : 0.5 * (t - 1) * (t - 1);
  x[1] = t;
  return 0;
}

/* ---- stewart-anitescu: x' in 2 - sign(x) with the running cost q' = x^2 ---- */
static int sa_field(int sys, int mode, double t, const double *x, const double *u, double *f, void *user) {
  (void)sys, (void)u, (void)user;
  f[0] = mode == 0 ? 1.0 : 3.0;
  f[1] = x[0] * x[0];
  return 0;
}
static int sa_field_jac(int sys, int mode, double t, const double *x, const double *u, double *J, double *Ju,
                        void *user) {
  (void)sys, (void)mode, (void)u, (void)Ju, (void)user;
  J[0] = 0;
  J[1] = 2 * x[0];
  J[2] = 0;
  J[3] = 0;
  return 0;
}

/* ---- slide-exit-2d (notes/sliding_exit.md): sliding on the curved surface
 * c = x1 + x2^2/2 from x0 = 0, leaving it when the sliding multiplier of the c < 0 mode
 * reaches 0. mode 0 (c > 0): f = (-1 + x2, (1 + x2^2)/2); mode 1: f = (1 + x2, (1 + x2^2)/2 + x2/2) */
static int se_field(int sys, int mode, double t, const double *x, const double *u, double *f, void *user) {
  (void)sys, (void)u, (void)user;
  f[0] = (mode == 0 ? -1.0 : 1.0) + x[1];
  f[1] = 0.5 * (1 + x[1] * x[1]) + (mode == 0 ? 0.0 : 0.5 * x[1]);
  return 0;
}
static int se_field_jac(int sys, int mode, double t, const double *x, const double *u, double *J, double *Ju,
                        void *user) {
  (void)sys, (void)u, (void)Ju, (void)user;
  J[0] = 0;
  J[1] = 0;
  J[2] = 1;
  J[3] = x[1] + (mode == 0 ? 0.0 : 0.5);
  return 0;
}
static int se_sw(int sys, double t, const double *x, const double *u, double *c, void *user) {
  (void)sys, (void)u, (void)user;
  c[0] = x[0] + 0.5 * x[1] * x[1];
  return 0;
}
static int se_sw_jac(int sys, double t, const double *x, const double *u, double *J, double *Ju, void *user) {
  (void)sys, (void)u, (void)Ju, (void)user;
  J[0] = 1;
  J[1] = x[1];
  return 0;
}
/* sliding multiplier of mode 1 and the sliding speed of x2 */
static double se_theta1(double y) { return (1 - 1.5 * y - 0.5 * y * y * y) / (2 + 0.5 * y * y); }
static double se_speed(double y) { return 0.5 * (1 + y * y) + 0.5 * y * se_theta1(y); }

void fesd_problem_slide_exit_point(double *t_exit, double *x2_exit) {
  double a = 0, b = 1; /* theta1(0) = 0.5 > 0 > theta1(1): bisection on the cubic */
  for (int i = 0; i < 200; i++) {
    double m = 0.5 * (a + b);
    if (se_theta1(m) > 0) a = m; else b = m;
  }
  double y = 0.5 * (a + b), h = y / 4000, acc = 0; /* composite Simpson for int dy / speed */
  for (int i = 0; i < 4000; i++) {
    double y0 = i * h;
    acc += h / 6 * (1 / se_speed(y0) + 4 / se_speed(y0 + h / 2) + 1 / se_speed(y0 + h));
  }
  *t_exit = acc;
  *x2_exit = y;
}

static int se_exact(double t, double *x) {
  double ts, ys;
  fesd_problem_slide_exit_point(&ts, &ys);
  if (t < ts) return -1; /* the sliding phase has no closed form */
  double ph = atan(ys), arg = 0.5 * (t - ts) + ph;
  x[1] = tan(arg);
  x[0] = -0.5 * ys * ys - (t - ts) - 2 * log(cos(arg)) + 2 * log(cos(ph));
  return 0;
}

/* ---- ocp-dynamics (paper Sec. 5): q' = -sign(c(q)) + v, v' = u, two subsystems ---- */
static const int two_sys_modes[2] = {2, 2};
static const int two_sys_switch[2] = {1, 1};
static int ocp_field(int sys, int mode, double t, const double *x, const double *u, double *f, void *user) {
  (void)user;
  double sg = mode == 0 ? -1.0 : 1.0; /* mode 0: c_k > 0 -> -sign = -1 */
  if (sys == 0) {
    f[0] = sg + x[2];
    f[1] = x[3];
    f[2] = u[0];
    f[3] = u[1];
  } else {
    f[0] = 0;
    f[1] = sg;
    f[2] = 0;
    f[3] = 0;
  }
  return 0;
}
static int ocp_field_jac(int sys, int mode, double t, const double *x, const double *u, double *J, double *Ju,
                         void *user) {
  (void)mode, (void)x, (void)u, (void)user;
  memset(J, 0, 16 * sizeof(double));
  if (Ju) memset(Ju, 0, 8 * sizeof(double));
  if (sys == 0) {
    J[2 * 4 + 0] = 1; /* df0/dx2 */
    J[3 * 4 + 1] = 1; /* df1/dx3 */
    if (Ju) {
      Ju[0 * 4 + 2] = 1;
      Ju[1 * 4 + 3] = 1;
    }
  }
  return 0;
}
static int ocp_sw(int sys, double t, const double *x, const double *u, double *c, void *user) {
  (void)u, (void)user;
  c[0] = sys == 0 ? x[0] + 0.15 * x[1] * x[1] : -0.05 * x[0] * x[0] * x[0] + x[1];
  return 0;
}
static int ocp_sw_jac(int sys, double t, const double *x, const double *u, double *J, double *Ju, void *user) {
  (void)u, (void)user;
  if (sys == 0) {
    J[0] = 1;
    J[1] = 0.3 * x[1];
  } else {
    J[0] = -0.15 * x[0] * x[0];
    J[1] = 1;
  }
  J[2] = J[3] = 0;
  if (Ju) Ju[0] = Ju[1] = 0;
  return 0;
}

/* ocp-dynamics with u = 0: q1 = 2pi/3 - t until 2pi/3; q2 = pi/3 - t until c2 = 0 at t1,
 * then q2 = 0.05 q1^3 (sliding on c2 = 0); the origin from 2pi/3 on; v = 0. */
double fesd_problem_ocp_t1(void) {
  const double t2 = 2 * PI / 3;
  double a = 0, b = 1.5;
  for (int i = 0; i < 200; i++) {
    double m = 0.5 * (a + b), q1 = t2 - m;
    if (-0.05 * q1 * q1 * q1 + (t2 / 2 - m) > 0) a = m; else b = m;
  }
  return 0.5 * (a + b);
}
static int ocp_exact(double t, double *x) {
  const double t2 = 2 * PI / 3, t1 = fesd_problem_ocp_t1();
  double q1 = t < t2 ? t2 - t : 0;
  x[0] = q1;
  x[1] = t < t1 ? PI / 3 - t : 0.05 * q1 * q1 * q1;
  x[2] = x[3] = 0;
  return 0;
}

static const char *const names[] = {"oscillator", "sign-a",       "sign-b",       "sign-c",
                                    "sign-d",     "nonlipschitz", "ocp-dynamics", "stewart-anitescu",
                                    "slide-exit-2d", "stick-slip", NULL};

const char *const *fesd_problem_names(void) { return names; }

static void scalar_problem(fesd_problem *p, const scalar_law *law, double x0, double T) {
  p->model = (fesd_model){.nx = 2, .nu = 0, .nsys = 1, .n_modes = one_sys_two_modes, .n_switch = one_switch, .sign = NULL, .field = scalar_field, .field_jac = scalar_field_jac, .sw = scalar_sw, .sw_jac = scalar_sw_jac, .user = (void *)law, .sparsity = NULL};
  p->x0[0] = x0;
  p->x0[1] = 0;
  p->T = T;
}

int fesd_problem_get(const char *name, fesd_problem *p) {
  if (!name || !p) return FESD_ERR_NULL;
  memset(p, 0, sizeof(*p));
  p->t_switch = NAN;
  if (!strcmp(name, "oscillator")) {
    p->name = "oscillator";
    p->description = "x' = A1 x outside / A2 x inside the unit circle; crossing at t = 1";
    p->model = (fesd_model){.nx = 2, .nu = 0, .nsys = 1, .n_modes = one_sys_two_modes, .n_switch = one_switch, .sign = NULL, .field = osc_field, .field_jac = osc_field_jac, .sw = osc_sw, .sw_jac = osc_sw_jac, .user = NULL, .sparsity = NULL};
    p->x0[0] = exp(-1.0);
    p->T = PI / 2;
    p->t_switch = 1.0;
    p->exact = fesd_problem_oscillator_exact;
  } else if (!strcmp(name, "stick-slip")) {
    p->name = "stick-slip";
    p->description = "friction oscillator on a belt: stuck until t = 2, then a stick-slip cycle";
    p->model = (fesd_model){.nx = 2, .nsys = 1, .n_modes = one_sys_two_modes, .n_switch = one_switch,
                            .field = fesd_stick_slip_field, .field_jac = fesd_stick_slip_field_jac,
                            .sw = fesd_stick_slip_sw, .sw_jac = fesd_stick_slip_sw_jac};
    p->x0[0] = 0;
    p->x0[1] = 1;
    p->T = 2 + 3 * fesd_stick_slip_reference().period;
    p->t_switch = 2.0;
    p->exact = fesd_stick_slip_exact;
  } else if (!strcmp(name, "sign-a")) {
    p->name = "sign-a";
    p->description = "x' in 2 - sign(x), x0 = -1: crossing at t = 1/3";
    scalar_problem(p, &law_a, -1.0, 1.0);
    p->t_switch = 1.0 / 3;
    p->exact = exact_a;
  } else if (!strcmp(name, "sign-b")) {
    p->name = "sign-b";
    p->description = "x' in -sign(x), x0 = 1: reaches 0 at t = 1 and slides";
    scalar_problem(p, &law_b, 1.0, 2.1);
    p->t_switch = 1.0;
    p->exact = exact_b;
  } else if (!strcmp(name, "sign-c")) {
    p->name = "sign-c";
    p->description = "x' in -sign(x) + t, x0 = 0: slides until t = 1, then x = (t-1)^2/2";
    scalar_problem(p, &law_c, 0.0, 2.1);
    p->t_switch = 1.0;
    p->exact = exact_c;
  } else if (!strcmp(name, "sign-d")) {
    p->name = "sign-d";
    p->description = "x' in sign(x), x0 = 0: non-unique (any Filippov solution)";
    scalar_problem(p, &law_d, 0.0, 1.0);
  } else if (!strcmp(name, "nonlipschitz")) {
    p->name = "nonlipschitz";
    p->description = "x' in 2 - sign(x) + x^2, x0 = -0.2, T = 0.2";
    scalar_problem(p, &law_nl, -0.2, 0.2);
  } else if (!strcmp(name, "ocp-dynamics")) {
    p->name = "ocp-dynamics";
    p->description = "q' = -sign(c(q)) + v, v' = u = 0: sliding on c1 = 0, then on c = 0";
    p->model = (fesd_model){.nx = 4, .nu = 2, .nsys = 2, .n_modes = two_sys_modes, .n_switch = two_sys_switch, .sign = NULL, .field = ocp_field, .field_jac = ocp_field_jac, .sw = ocp_sw, .sw_jac = ocp_sw_jac, .user = NULL, .sparsity = NULL};
    p->x0[0] = 2 * PI / 3;
    p->x0[1] = PI / 3;
    p->T = 4.0;
    p->t_switch = fesd_problem_ocp_t1();
    p->exact = ocp_exact;
  } else if (!strcmp(name, "stewart-anitescu")) {
    p->name = "stewart-anitescu";
    p->description = "x' in 2 - sign(x), q' = x^2 (running cost), x0 = (-1, 0), T = 2";
    p->model = (fesd_model){.nx = 2, .nu = 0, .nsys = 1, .n_modes = one_sys_two_modes, .n_switch = one_switch, .sign = NULL, .field = sa_field, .field_jac = sa_field_jac, .sw = scalar_sw, .sw_jac = scalar_sw_jac, .user = NULL, .sparsity = NULL};
    p->x0[0] = -1.0;
    p->T = 2.0;
    p->t_switch = 1.0 / 3;
  } else if (!strcmp(name, "slide-exit-2d")) {
    p->name = "slide-exit-2d";
    p->description = "slides on c = x1 + x2^2/2 from x0 = 0, leaves it at t = 1.02617735";
    p->model = (fesd_model){.nx = 2, .nu = 0, .nsys = 1, .n_modes = one_sys_two_modes, .n_switch = one_switch, .sign = NULL, .field = se_field, .field_jac = se_field_jac, .sw = se_sw, .sw_jac = se_sw_jac, .user = NULL, .sparsity = NULL};
    p->T = 2.1;
    double x2;
    fesd_problem_slide_exit_point(&p->t_switch, &x2);
    p->exact = se_exact;
  } else {
    return FESD_ERR_INVALID_ARG;
  }
  return FESD_OK;
}

/* ---- Stewart-Anitescu value function (paper Sec. 4.5, Fig. ivp_problem) ---- */

double fesd_sa_exact_value(double x0, double *dV) {
  double V, d;
  if (x0 >= 0) {
    V = ((x0 + 2) * (x0 + 2) * (x0 + 2) - x0 * x0 * x0) / 3 + (x0 + 1.0 / 3) * (x0 + 1.0 / 3);
    d = (x0 + 2) * (x0 + 2) - x0 * x0 + 2 * (x0 + 1.0 / 3);
  } else {
    double a = 2 + x0 / 3, b = (1 + x0) / 3;
    V = -x0 * x0 * x0 / 9 + a * a * a / 3 + b * b;
    d = -x0 * x0 / 3 + a * a / 3 + 2 * b / 3;
  }
  if (dV) *dV = d;
  return V;
}

int fesd_sa_value(fesd_integrator *it, double x0, int nsim, double *V, double *dV) {
  double x[2] = {x0, 0}, S[4];
  int st = fesd_set_state(it, 0, x, NULL);
  for (int k = 0; k < nsim && !st; k++) st = fesd_step(it, NULL, 2.0 / nsim, NULL);
  if (st) return st;
  fesd_get_state(it, NULL, x);
  if ((st = fesd_get_sensitivities(it, S, NULL))) return st;
  *V = x[1] + (x[0] - 5.0 / 3) * (x[0] - 5.0 / 3);
  *dV = S[1] + 2 * (x[0] - 5.0 / 3) * S[0]; /* column 0: d(x, q)(T)/dx0 */
  return FESD_OK;
}

int fesd_sa_shoot(fesd_integrator *it, double x_start, int nsim, double *x_opt, int *iters) {
  double xa = x_start, xb = x_start + 1e-2, Va, Vb, ga, gb;
  int st = fesd_sa_value(it, xa, nsim, &Va, &ga);
  if (!st) st = fesd_sa_value(it, xb, nsim, &Vb, &gb);
  int k = 0;
  for (; k < 100 && !st; k++) {
    if (fabs(gb) <= 1e-12 || gb == ga) break;
    double step = -gb * (xb - xa) / (gb - ga); /* secant on dV/dx0 */
    if (step > 1) step = 1;
    if (step < -1) step = -1;
    xa = xb, ga = gb;
    xb = xb + step;
    st = fesd_sa_value(it, xb, nsim, &Vb, &gb);
    if (fabs(step) <= 1e-13 * fmax(1, fabs(xb))) break;
  }
  *x_opt = xb;
  *iters = k;
  return st;
}
