/* Co-dimension-2 corners: two subsystems with switching functions c_k = n_k . x (lines
 * through the origin) and piecewise-constant fields, x' = f_1(side of c_1) + f_2(side of c_2)
 * in R^2 (paper Sec. 2.3: each subsystem convexified on its own). Exact solutions are
 * piecewise linear. Design A: both lines attract from both sides and the corner is a sliding
 * equilibrium (theta_1, theta_2 in (0,1)): every trajectory reaches a line, slides along it
 * into the corner and stays (the second subsystem enters sliding while the first slides).
 * Design B (tilted lines): the corner is no equilibrium (theta_1 would be > 1): trajectories
 * sliding on c_1 = 0 pass the corner and slide on along c_2 = 0 (exit of subsystem 1 and entry
 * of subsystem 2 at once); c_1 = 0 is crossed where c_2 < 0, and also at the corner by
 * trajectories sliding on c_2 = 0.
 * Reference, independent of the library: event-driven on the exact pieces; at every event
 * each of the 9 combinations (mode 0 / mode 1 / sliding per subsystem) is tried and the
 * unique consistent one kept (sliding: theta from n_k . x' = 0 in (0,1); a mode on its line:
 * x' leaves into its side), asserted unique. Event times are divisions (-c_k / n_k . x').
 * 50 seeded random starts per design whose events are >= 0.02 apart, plus direct hits of the
 * corner from each quadrant; Radau IIA s = 2, 3 and N_sim = 7, 13, 40 (argument "families": Lobatto
 * IIIA, Lobatto IIIC and Gauss-Legendre instead). Asserted: every run
 * completes, the state at every element boundary is exact to 1e-12 (relative), the events
 * (time to 1e-12, subsystem, kind) are the reference's. */
#include "hard_util.h"

typedef struct {
  double f[2][2][2]; /* [subsystem][mode][component]: mode 0 where c > 0 */
  double n[2][2];    /* normals of the lines c_k = n_k . x */
  const char *name;
} design;
static const design DA = {{{{-1, 0.2}, {1, -0.1}}, {{0.4, -1}, {-0.3, 1}}}, {{1, 0}, {0, 1}}, "A"};
static const design DB = {{{{-1, 0.1}, {1, -0.2}}, {{0.5, -1}, {2, 1}}}, {{1, 0.2}, {-0.15, 1}}, "B"};

static int field(int sys, int mode, double t, const double *x, const double *u, double *f, void *user) {
  const design *D = user;
  f[0] = D->f[sys][mode][0], f[1] = D->f[sys][mode][1];
  return 0;
}
static int sw(int sys, double t, const double *x, const double *u, double *c, void *user) {
  const design *D = user;
  c[0] = D->n[sys][0] * x[0] + D->n[sys][1] * x[1];
  return 0;
}

static double dot(const double *a, const double *b) { return a[0] * b[0] + a[1] * b[1]; }

/* velocity of a combination (cfg_k: 0, 1 = mode, 2 = sliding); returns 0 if a theta of a
 * sliding subsystem is outside (0,1) (margin 1e-9) or undetermined */
static int velocity(const design *D, const int *cfg, double *v) {
  double th[2] = {0, 0}, base[2] = {0, 0}, d[2][2];
  int sl[2], ns = 0;
  for (int k = 0; k < 2; k++) {
    const double *fm = D->f[k][cfg[k] == 0 ? 0 : 1];
    base[0] += fm[0], base[1] += fm[1]; /* sliding: theta f_0 + (1 - theta) f_1 = f_1 + theta d */
    d[k][0] = D->f[k][0][0] - D->f[k][1][0], d[k][1] = D->f[k][0][1] - D->f[k][1][1];
    if (cfg[k] == 2) sl[ns++] = k;
  }
  if (ns == 1) {
    int k = sl[0];
    th[k] = -dot(D->n[k], base) / dot(D->n[k], d[k]);
  } else if (ns == 2) { /* n_k . (base + th_0 d_0 + th_1 d_1) = 0, k = 0, 1: Cramer */
    double a = dot(D->n[0], d[0]), b = dot(D->n[0], d[1]), c = dot(D->n[1], d[0]), e = dot(D->n[1], d[1]);
    double r0 = -dot(D->n[0], base), r1 = -dot(D->n[1], base), det = a * e - b * c;
    if (fabs(det) < 1e-12) return 0;
    th[0] = (r0 * e - b * r1) / det, th[1] = (a * r1 - c * r0) / det;
  }
  for (int j = 0; j < ns; j++)
    if (!(th[sl[j]] > 1e-9 && th[sl[j]] < 1 - 1e-9)) return 0;
  for (int i = 0; i < 2; i++) v[i] = base[i] + th[0] * d[0][i] + th[1] * d[1][i];
  return 1;
}

#define MAXE 16
typedef struct {
  int n, n_ev, ambiguous;
  double t[MAXE + 1], x[MAXE + 1][2], v[MAXE][2]; /* piece p: x = x[p] + v[p] (t - t[p]) */
  double ev_t[MAXE];
  int ev_sys[MAXE], ev_kind[MAXE];
  double min_gap;
} pl_ref;

static void reference(const design *D, const double *x0, double T, pl_ref *R) {
  double c[2], x[2] = {x0[0], x0[1]}, t = 0;
  int cfg[2];
  memset(R, 0, sizeof(*R));
  R->min_gap = INFINITY;
  for (int k = 0; k < 2; k++) c[k] = dot(D->n[k], x), cfg[k] = c[k] > 0 ? 0 : 1;
  for (;;) {
    int p = R->n++;
    double v[2];
    velocity(D, cfg, v);
    R->t[p] = t, R->x[p][0] = x[0], R->x[p][1] = x[1], R->v[p][0] = v[0], R->v[p][1] = v[1];
    double tau = INFINITY, tk[2] = {INFINITY, INFINITY};
    for (int k = 0; k < 2; k++) {
      double rate = dot(D->n[k], v);
      if (cfg[k] != 2 && c[k] * rate < 0) tk[k] = -c[k] / rate, tau = fmin(tau, tk[k]);
    }
    if (t + tau >= T || p == MAXE - 1) break;
    R->min_gap = fmin(R->min_gap, tau);
    t += tau, x[0] += tau * v[0], x[1] += tau * v[1];
    int on[2];
    for (int k = 0; k < 2; k++) {
      on[k] = cfg[k] == 2 || tk[k] <= tau * (1 + 1e-12); /* ties: a direct hit of the corner */
      c[k] = on[k] ? 0 : c[k] + tau * dot(D->n[k], v);
    }
    int found = 0, nc[2] = {0, 0};
    for (int a = 0; a < 3; a++)
      for (int b = 0; b < 3; b++) {
        int q[2] = {a, b}, ok = 1;
        double w[2];
        for (int k = 0; k < 2; k++) ok &= on[k] || q[k] == cfg[k];
        if (!ok || !velocity(D, q, w)) continue;
        for (int k = 0; k < 2; k++)
          if (on[k] && q[k] != 2) ok &= q[k] == 0 ? dot(D->n[k], w) > 1e-9 : dot(D->n[k], w) < -1e-9;
        if (ok) found++, nc[0] = a, nc[1] = b;
      }
    R->ambiguous |= found != 1;
    for (int k = 0; k < 2; k++)
      if (nc[k] != cfg[k] && R->n_ev < MAXE) {
        R->ev_t[R->n_ev] = t, R->ev_sys[R->n_ev] = k;
        R->ev_kind[R->n_ev++] = nc[k] == 2 ? FESD_EVENT_SLIDING_ENTRY
                                           : (cfg[k] == 2 ? FESD_EVENT_SLIDING_EXIT : FESD_EVENT_CROSSING);
      }
    cfg[0] = nc[0], cfg[1] = nc[1];
  }
  R->t[R->n] = T;
}
static void ref_state(const pl_ref *R, double t, double *x) {
  int p = 0;
  while (p + 1 < R->n && R->t[p + 1] <= t) p++;
  x[0] = R->x[p][0] + R->v[p][0] * (t - R->t[p]), x[1] = R->x[p][1] + R->v[p][1] * (t - R->t[p]);
}

static unsigned long long rng = 0x9E3779B97F4A7C15ull;
static double urand(void) { /* LCG (Knuth MMIX), uniform in [-1, 1) */
  rng = rng * 6364136223846793005ull + 1442695040888963407ull;
  return (double)(rng >> 11) / 4503599627370496.0 - 1;
}

int main(int argc, char **argv) {
  int fails = 0;
  /* argument "families": the other implicit families (exact on piecewise-constant fields too) */
  const fesd_rk_family radau[] = {FESD_RK_RADAU_IIA},
                       others[] = {FESD_RK_LOBATTO_IIIA, FESD_RK_LOBATTO_IIIC, FESD_RK_GAUSS_LEGENDRE};
  const int fam_others = argc > 1 && !strcmp(argv[1], "families"), n_fam = fam_others ? 3 : 1;
  const fesd_rk_family *fams = fam_others ? others : radau;
  static hd_run H;
  static pl_ref R;
  const int nm[2] = {2, 2}, ns[2] = {1, 1}, nsims[3] = {7, 13, 40};
  const double T = 3.5;
  for (int dsg = 0; dsg < 2; dsg++) {
    const design *D = dsg ? &DB : &DA;
    fesd_model m = {.nx = 2, .nsys = 2, .n_modes = nm, .n_switch = ns, .field = field, .sw = sw, .user = (void *)D};
    int runs = 0, failed = 0, n_starts = 0, n_direct = 0, kinds[3] = {0, 0, 0}, corner_runs = 0;
    double worst = 0, worst_ev = 0;
    for (int start = 0; start < 50 + 4; start++) {
      double x0[2];
      if (start < 50) { /* random, with well-separated events */
        do {
          x0[0] = urand(), x0[1] = urand();
          reference(D, x0, T, &R);
        } while (R.min_gap < 0.02 || R.ambiguous || fabs(dot(D->n[0], x0)) < 0.02 || fabs(dot(D->n[1], x0)) < 0.02);
      } else { /* straight into the corner from quadrant q at t = 0.75, where its field points there */
        int q = start - 50, cfg[2] = {q & 1, q >> 1};
        double v[2];
        velocity(D, cfg, v);
        x0[0] = -0.75 * v[0], x0[1] = -0.75 * v[1];
        if (dot(D->n[0], x0) * (cfg[0] ? -1 : 1) <= 0 || dot(D->n[1], x0) * (cfg[1] ? -1 : 1) <= 0) continue;
        reference(D, x0, T, &R);
        n_direct++;
        HD_CHECK(R.n_ev >= 1 && fabs(R.ev_t[0] - 0.75) < 1e-12, "design %s corner start %d: reference", D->name, q);
      }
      HD_CHECK(!R.ambiguous, "design %s start %d: reference ambiguous", D->name, start);
      n_starts++;
      int corner = 0;
      for (int e = 0; e < R.n_ev; e++) {
        kinds[R.ev_kind[e]]++;
        double xe[2];
        ref_state(&R, R.ev_t[e], xe);
        corner |= hd_maxdiff(xe, (double[2]){0, 0}, 2) < 1e-12;
      }
      for (int fi = 0; fi < n_fam; fi++)
      for (int s = 2; s <= 3; s++)
        for (int g = 0; g < 3; g++) {
          fesd_settings set;
          fesd_settings_default(&set);
          set.stages = s;
          set.family = fams[fi];
          int st = hd_integrate(&m, &set, 0, x0, NULL, T, nsims[g], &H);
          runs++, corner_runs += corner;
          if (st) {
            failed++;
            HD_CHECK(0, "design %s start %d (x0 = %.17g, %.17g) %s s=%d N_sim=%d: %s at step %d (t = %.6f, path %s)",
                     D->name, start, x0[0], x0[1], fesd_rk_family_name(fams[fi]), s, nsims[g], fesd_status_name(st), H.steps_done, H.t_end,
                     H.info.failed_path ? H.info.failed_path : "-");
            continue;
          }
          double err = 0, ev_err = 0, xe[2];
          for (int e = 0; e <= H.n_el; e++) {
            ref_state(&R, H.t[e], xe);
            err = fmax(err, hd_maxdiff(H.x[e], xe, 2) / fmax(1, fmax(fabs(xe[0]), fabs(xe[1]))));
          }
          int match = H.n_ev == R.n_ev;
          for (int e = 0; e < R.n_ev && match; e++) { /* simultaneous events may come in any order */
            double best = INFINITY;
            for (int f = 0; f < H.n_ev; f++)
              if (H.ev[f].sys == R.ev_sys[e] && (int)H.ev[f].kind == R.ev_kind[e])
                best = fmin(best, fabs(H.ev[f].t - R.ev_t[e]));
            match = best <= 1e-12;
            ev_err = fmax(ev_err, best);
          }
          worst = fmax(worst, err), worst_ev = fmax(worst_ev, ev_err);
          HD_CHECK(err <= 1e-12 && match, "design %s start %d (x0 = %.17g, %.17g) %s s=%d N_sim=%d: state err %.1e, "
                   "%d events (reference %d), matched %d (time err %.1e)", D->name, start, x0[0], x0[1],
                   fesd_rk_family_name(fams[fi]), s, nsims[g],
                   err, H.n_ev, R.n_ev, match, ev_err);
        }
    }
    printf("corner design %s: %d starts (%d straight into the corner), reference events: %d crossings, %d entries, %d exits; %d runs (%d reach "
           "the corner), %d failed; max state err %.1e, max event time err %.1e\n", D->name, n_starts, n_direct, kinds[0],
           kinds[1], kinds[2], runs, corner_runs, failed, worst, worst_ev);
  }
  printf("%d failures\n", fails);
  return fails != 0;
}
