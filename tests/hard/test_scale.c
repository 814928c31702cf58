/* Scale invariance and a long run: x' in -sign(x) + A sin(tau), tau' = 1 (time carried as a
 * state), x(0) = 0.5, tau(0) = 0, for A = 2 (as issue 15 states it: the solution settles on a
 * periodic orbit with two crossings per period and never slides, since it always returns to
 * x = 0 where |A sin tau| > 1) and A = 1.5 (slides on x = 0 while |A sin tau| < 1, leaves
 * tangentially when A sin tau = +-1, at tau = asin(1/A) + j pi: two entries and two exits per
 * period). Exact pieces: x = x_p -+ (t - t_p) + 2A sin((t + t_p)/2) sin((t - t_p)/2), roots by
 * sampling and bisection, exits in closed form; sliding forgets the past, crossings do not.
 * Without argument: every state (x and tau) scaled by a = 1e8 and 1e-8, then x alone (the
 * model adapted: x~ = a x, tau~ = b tau, x~' = a (-+1 + A sin(tau~/b)), tau~' = b, c = x~);
 * the relative errors at the step ends must be those of the unscaled run within a factor 10
 * and the events the same. Argument "long": 10^6 steps of h = 0.05 (t up to 5e4), every step
 * FESD_OK, every event of the reference in kind and order, small errors. Radau IIA s = 2,
 * N_FE = 2 (defaults). Printed too: t and tau against N_sim h at the end (round-off of the
 * summed step and element lengths, ~1e-6 at 5e4; it enters the event times). */
#include "hard_util.h"

#define MAXPH 40000
typedef struct {
  double A, ax, at; /* amplitude, scales of x and tau */
} model_par;

static int field(int sys, int mode, double t, const double *x, const double *u, double *f, void *user) {
  const model_par *P = user;
  f[0] = P->ax * ((mode == 0 ? -1 : 1) + P->A * sin(x[1] / P->at));
  f[1] = P->at;
  return 0;
}
static int field_jac(int sys, int mode, double t, const double *x, const double *u, double *J, double *Ju, void *user) {
  const model_par *P = user;
  J[0] = J[1] = J[3] = 0, J[2] = P->ax / P->at * P->A * cos(x[1] / P->at);
  return 0;
}
static int sw(int sys, double t, const double *x, const double *u, double *c, void *user) {
  c[0] = x[0];
  return 0;
}
static int sw_jac(int sys, double t, const double *x, const double *u, double *J, double *Ju, void *user) {
  J[0] = 1, J[1] = 0;
  return 0;
}

/* ---- reference: phases 0 (x > 0), 1 (x < 0), 2 (sliding); phase p starts at t[p] from x = 0
 * (p > 0) or x = 0.5 (p = 0); kind[p]: the event that opened it ---- */
static struct {
  int n;
  double A, t[MAXPH + 1];
  signed char mode[MAXPH], kind[MAXPH];
} R;

static double piece(int p, double t) {
  if (R.mode[p] == 2) return 0;
  const double tp = R.t[p];
  return (p ? 0 : 0.5) + (R.mode[p] ? 1 : -1) * (t - tp) + 2 * R.A * sin((t + tp) / 2) * sin((t - tp) / 2);
}
static void reference_run(double A, double T) {
  const double th = A > 1 ? asin(1 / A) : 0;
  double t = 0;
  int mode = 0;
  R.A = A;
  for (R.n = 0; R.n < MAXPH;) {
    int p = R.n++;
    R.t[p] = t, R.mode[p] = mode;
    if (mode == 2) { /* exit at the next tau = th + j pi: j even to x > 0, odd to x < 0 */
      double j = floor((t - th) / HD_PI) + 1;
      t = th + j * HD_PI, mode = fmod(j, 2) == 0 ? 0 : 1;
      R.kind[R.n] = FESD_EVENT_SLIDING_EXIT;
    } else { /* first root of the piece after t (sampled at 0.01, bisection) */
      const double sg = mode ? -1 : 1, dt = 0.01;
      double lo = t, hi = t + dt;
      while (sg * piece(p, hi) > 0 && hi < T + 1) lo = hi, hi += dt;
      for (int i = 0; i < 60; i++) {
        double mid = 0.5 * (lo + hi);
        if (sg * piece(p, mid) > 0) lo = mid; else hi = mid;
      }
      t = 0.5 * (lo + hi);
      int slide = mode ? -1 + A * sin(t) < 0 : 1 + A * sin(t) > 0; /* the other field points back */
      R.kind[R.n] = slide ? FESD_EVENT_SLIDING_ENTRY : FESD_EVENT_CROSSING;
      mode = slide ? 2 : 1 - mode;
    }
    if (t > T) break;
  }
  R.t[R.n] = INFINITY;
}
static double ref_x(double t) {
  int lo = 0, hi = R.n - 1; /* last phase starting at or before t */
  while (lo < hi) {
    int mid = (lo + hi + 1) / 2;
    if (R.t[mid] <= t) lo = mid; else hi = mid - 1;
  }
  return piece(lo, t);
}

/* nsim steps of h from (0.5, 0), x scaled by ax and tau by at: largest relative error of x at
 * the step ends (against the reference at the step's tau), events compared in order with the
 * reference's. */
typedef struct {
  int status, fail_step, n_ev, ev_bad;
  double err, ev_err, err_end, t_end, tau_end;
  fesd_step_info info;
  fesd_stats stats;
} outcome;
static void run(double A, double a, double at, int nsim, double h, outcome *o) {
  model_par P = {A, a, at};
  const int nm[1] = {2}, ns[1] = {1};
  fesd_model m = {.nx = 2, .nsys = 1, .n_modes = nm, .n_switch = ns, .field = field, .field_jac = field_jac,
                  .sw = sw, .sw_jac = sw_jac, .user = &P};
  fesd_settings set;
  fesd_settings_default(&set);
  memset(o, 0, sizeof(*o));
  fesd_integrator *it;
  o->status = fesd_create(&it, &m, &set);
  if (o->status) return;
  const double x0[2] = {0.5 * a, 0};
  o->status = fesd_set_state(it, 0, x0, NULL);
  double x[2], t;
  for (int k = 0; k < nsim && !o->status; k++) {
    o->status = fesd_step(it, NULL, h, &o->info);
    if (o->status) {
      o->fail_step = k;
      break;
    }
    const fesd_event *ev;
    int ne;
    fesd_last_events(it, &ev, &ne);
    for (int e = 0; e < ne; e++, o->n_ev++) {
      int q = o->n_ev + 1; /* phase opened by this event */
      if (q >= R.n || (int)ev[e].kind != R.kind[q]) {
        o->ev_bad++;
        continue;
      }
      o->ev_err = fmax(o->ev_err, fabs(ev[e].t - R.t[q]));
    }
    fesd_get_state(it, &t, x);
    o->err = fmax(o->err, fabs(x[0] / a - ref_x(x[1] / at)));
  }
  fesd_get_stats(it, &o->stats);
  o->err_end = fabs(x[0] / a - ref_x(x[1] / at));
  o->t_end = t, o->tau_end = x[1] / at;
  fesd_free(&it);
}

int main(int argc, char **argv) {
  int fails = 0;
  const int longrun = argc > 1 && !strcmp(argv[1], "long");
  const double amp[2] = {2.0, 1.5};
  for (int i = 0; i < 2; i++) {
    const double A = amp[i], h = 0.05;
    const int nsim = longrun ? 1000000 : 2000;
    reference_run(A, nsim * h);
    int n_ref = 0, kinds[3] = {0, 0, 0};
    for (int p = 1; p < R.n && R.t[p] <= nsim * h; p++) n_ref++, kinds[R.kind[p]]++;
    printf("reference A = %g, t <= %g: %d events (%d crossings, %d entries, %d exits)\n", A, nsim * h, n_ref, kinds[0],
           kinds[1], kinds[2]);
    HD_CHECK(A == 2 ? kinds[0] == n_ref && n_ref > 0 : kinds[1] == kinds[2] && kinds[1] > 0 && !kinds[0],
             "reference A = %g: event kinds %d %d %d", A, kinds[0], kinds[1], kinds[2]);
    /* scales of (x, tau): both, then x alone */
    const double scales[5][2] = {{1, 1}, {1e8, 1e8}, {1e-8, 1e-8}, {1e8, 1}, {1e-8, 1}};
    double err1 = 0;
    for (int j = 0; j < (longrun ? 1 : 5); j++) {
      outcome o;
      run(A, scales[j][0], scales[j][1], nsim, h, &o);
      HD_CHECK(o.status == FESD_OK, "A = %g, scales %g %g: %s at step %d (t = %.6f, path %s, residual %.1e)", A,
               scales[j][0], scales[j][1], fesd_status_name(o.status), o.fail_step, o.fail_step * h,
               o.info.failed_path ? o.info.failed_path : "-", o.info.failed_residual);
      HD_CHECK(o.n_ev == n_ref && o.ev_bad == 0 && o.ev_err <= 1e-5, "A = %g, scales %g %g: %d events (reference %d), "
               "%d of another kind or order, time err %.1e", A, scales[j][0], scales[j][1], o.n_ev, n_ref, o.ev_bad,
               o.ev_err);
      printf("A = %g, scales (x, tau) (%-5g, %-5g) N_sim = %d: %s, max rel err %.2e, final err %.2e, event time err "
             "%.2e, %d events, iters %d, splits %d; end: t - N_sim h %.1e, tau - N_sim h %.1e\n", A, scales[j][0],
             scales[j][1], nsim, fesd_status_name(o.status), o.err, o.err_end, o.ev_err, o.n_ev, o.stats.newton_iter,
             o.stats.splits, o.t_end - nsim * h, o.tau_end - nsim * h);
      if (j == 0) err1 = o.err;
      if (j > 0)
        HD_CHECK(o.err <= 10 * err1 && err1 <= 10 * o.err, "A = %g: relative error %.2e at scales %g %g, %.2e "
                 "unscaled", A, o.err, scales[j][0], scales[j][1], err1);
    }
    if (longrun) HD_CHECK(err1 <= 1e-5, "A = %g long run: max error %.1e", A, err1); /* 1e-7 measured */
  }
  printf("%d failures\n", fails);
  return fails != 0;
}
