/* Filippov's conditions at the switch points of coarse steps (randomised, seeded).
 * A relay driven by a ramping input, x' in -sign(x) + v, v' = a: the flow slides on x = 0 while
 * |v| < 1 and leaves when v reaches +-1, so whether an arrival crosses or slides, and when a
 * sliding mode ends, is decided by v at the switch time. On long elements whose only stage
 * is the element end (implicit Euler), or few stages, the discrete equations see v only at the
 * stages: a crossing into a region whose field points back at the switch, and an exit before v
 * reaches +-1, both satisfy them (measured before the switch-point check, src/fesd/verify.c).
 * Reference: the event-by-event closed form in this test (piecewise quadratic x, linear v).
 * Asserted for every FESD_OK run: the event sequence (kinds) of the reference, and the state at
 * T within a bound that scales with the method's order. Cases near a tie are left out: an
 * arrival with |v| within 0.05 of 1, an extremum of x's current piece within 5e-3 of 0 (a
 * grazing touch: Lobatto IIIC s = 3 on one element of 0.47 steps over a sliding phase of 0.046
 * under a bump 1.9e-3 high, unflagged, between its interior check points), events within 0.03
 * of each other or of the step ends. */
#include "hard_util.h"

typedef struct {
  double a;
} ramp;

static int f_ramp(int sys, int mode, double t, const double *x, const double *u, double *f, void *user) {
  (void)sys, (void)t, (void)u;
  f[0] = (mode == 0 ? -1.0 : 1.0) + x[1];
  f[1] = ((const ramp *)user)->a;
  return 0;
}
static int c_ramp(int sys, double t, const double *x, const double *u, double *c, void *user) {
  (void)sys, (void)t, (void)u, (void)user;
  c[0] = x[0];
  return 0;
}

#define MAX_REF 16
typedef struct {
  int n;
  double t[MAX_REF];
  int kind[MAX_REF];
  double x_end;
  int degenerate;
} ref_run;

/* smallest root in (0, tmax] of x + b tau + a tau^2 / 2, or INFINITY */
static double first_root(double x, double b, double a, double tmax) {
  double best = INFINITY;
  if (fabs(a) < 1e-14) {
    if (b != 0 && -x / b > 0) best = -x / b;
  } else {
    const double d = b * b - 2 * a * x;
    if (d >= 0) {
      const double q = -(b + copysign(sqrt(d), b)), r1 = q / a, r2 = q != 0 ? 2 * x / q : INFINITY;
      if (r1 > 0) best = fmin(best, r1);
      if (r2 > 0) best = fmin(best, r2);
    }
  }
  return best <= tmax ? best : INFINITY;
}

static void reference(double x, double v, double a, double T, const double *bounds, int nb, ref_run *R) {
  memset(R, 0, sizeof(*R));
  int r = x > 0 ? 1 : -1; /* region: +1, -1, or 0 sliding */
  double t = 0;
  while (t < T && R->n < MAX_REF) {
    double tau = INFINITY, rem = T - t;
    int kind = -1, r_next = r;
    if (r != 0) {
      const double b = -r + v;
      tau = first_root(x, b, a, rem);
      /* a grazing extremum inside the interval */
      if (a != 0) {
        const double te = -b / a;
        if (te > 0 && te < rem && fabs(x + b * te + a * te * te / 2) < 5e-3) R->degenerate = 1;
      }
      if (tau < INFINITY) {
        const double va = v + a * tau;
        if (fabs(fabs(va) - 1) < 0.05) R->degenerate = 1;
        if (fabs(va) < 1) kind = FESD_EVENT_SLIDING_ENTRY, r_next = 0;
        else kind = FESD_EVENT_CROSSING, r_next = -r;
      }
      const double dt = fmin(tau, rem);
      x = tau < INFINITY ? 0.0 : x + b * dt + a * dt * dt / 2;
      v += a * dt;
      t += dt;
    } else {
      if (a > 0) tau = (1 - v) / a, r_next = 1;
      if (a < 0) tau = (-1 - v) / a, r_next = -1;
      if (!(tau <= rem)) tau = INFINITY;
      else kind = FESD_EVENT_SLIDING_EXIT;
      const double dt = fmin(tau, rem);
      v += a * dt;
      t += dt;
    }
    if (kind < 0) break;
    R->t[R->n] = t;
    R->kind[R->n++] = kind;
    r = r_next;
  }
  R->x_end = x;
  for (int e = 0; e < R->n; e++) {
    if (e > 0 && R->t[e] - R->t[e - 1] < 0.03) R->degenerate = 1;
    for (int q = 0; q < nb; q++)
      if (fabs(R->t[e] - bounds[q]) < 0.03) R->degenerate = 1;
  }
}

static double urand(unsigned *s, double lo, double hi) {
  *s = *s * 1103515245u + 12345u;
  return lo + (hi - lo) * ((*s >> 8) & 0xffffff) / (double)0x1000000;
}

int main(void) {
  int fails = 0;
  static hd_run R;
  const int nm[1] = {2}, ns[1] = {1};
  const struct {
    fesd_rk_family fam;
    int s, order;
  } meth[] = {{FESD_RK_RADAU_IIA, 1, 1}, {FESD_RK_RADAU_IIA, 2, 3}, {FESD_RK_RADAU_IIA, 3, 5},
              {FESD_RK_LOBATTO_IIIC, 2, 2}, {FESD_RK_LOBATTO_IIIC, 3, 4}};
  const int nmeth = sizeof meth / sizeof meth[0], nsims[3] = {1, 2, 4};
  unsigned seed = 20261128u;
  int cases = 0, skipped = 0, ok = 0, failed = 0, wrong_events = 0, wrong_state = 0, unflagged = 0, flagged_ok = 0;
  for (int c = 0; c < 400; c++) {
    ramp P = {urand(&seed, -3, 3)};
    if (fabs(P.a) < 0.3) P.a = copysign(0.3, P.a);
    const double x0[2] = {urand(&seed, -0.25, 0.25), urand(&seed, -1.6, 1.6)}, T = urand(&seed, 0.5, 1.5);
    fesd_model m = {.nx = 2, .nsys = 1, .n_modes = nm, .n_switch = ns, .field = f_ramp, .sw = c_ramp, .user = &P};
    for (int q = 0; q < nmeth; q++)
      for (int g = 0; g < 3; g++) {
        double bounds[8];
        for (int b = 0; b <= nsims[g]; b++) bounds[b] = T * b / nsims[g];
        ref_run ref;
        reference(x0[0], x0[1], P.a, T, bounds, nsims[g] + 1, &ref);
        if (ref.degenerate || fabs(x0[0]) < 0.02) {
          skipped++;
          continue;
        }
        cases++;
        fesd_settings set;
        fesd_settings_default(&set);
        set.family = meth[q].fam;
        set.stages = meth[q].s;
        int st = hd_integrate(&m, &set, 0, x0, NULL, T, nsims[g], &R);
        if (st != FESD_OK) {
          failed++;
          continue;
        }
        ok++;
        int same = R.n_ev == ref.n;
        for (int e = 0; e < ref.n && same; e++) same = (int)R.ev[e].kind == ref.kind[e];
        /* state: the local error of the method on one step, from its order (constants measured
         * on the smooth pieces: h^(p+1) with h the step, x'' = a) plus the switch placement */
        const double h = T / nsims[g], bound = 2.0 * fabs(P.a) * pow(h, meth[q].order) + 1e-9;
        const double err = fabs(R.x_end[0] - ref.x_end);
        const int flagged = R.stats.coarse_steps + R.stats.ambiguous_steps > 0;
        flagged_ok += flagged;
        if (!same) {
          wrong_events++;
          unflagged += !flagged;
          if (!flagged) {
            printf("  case %d %s s=%d N=%d: a %.3f x0 (%.4f, %.4f) T %.3f: events", c,
                   meth[q].fam == FESD_RK_RADAU_IIA ? "radau" : "lobatto3c", meth[q].s, nsims[g], P.a, x0[0], x0[1], T);
            for (int e = 0; e < R.n_ev; e++) printf(" %d@%.4f", (int)R.ev[e].kind, R.ev[e].t);
            printf(" | reference");
            for (int e = 0; e < ref.n; e++) printf(" %d@%.4f", ref.kind[e], ref.t[e]);
            printf("\n");
          }
        } else if (err > bound && !flagged) {
          if (wrong_state++ < 8)
            printf("  case %d s=%d N=%d: x(T) error %.2e > %.2e\n", c, meth[q].s, nsims[g], err, bound);
        }
      }
  }
  printf("%d cases (%d near a tie skipped): %d FESD_OK (%d with a flagged step), %d failed with a status; of the "
         "OK: %d other event sequences than the flow's (%d unflagged), %d unflagged states beyond the bound\n",
         cases, skipped, ok, flagged_ok, failed, wrong_events, unflagged, wrong_state);
  /* Starts within round-off of the surface on the side whose field points at it (x0 = -d,
   * v0 in (-1, 0), a < 0: x reaches 0 after d / (1 + v0), slides until v = -1, leaves below):
   * the same events and end state as a start d above (whose field also points at the surface).
   * Before the start check (verify_between.c) implicit Euler stayed below on one element: end
   * states 0.3 apart for d = 1e-9. */
  int starts = 0, start_bad = 0, start_s1 = 0;
  for (int c = 0; c < 40; c++) {
    ramp P2 = {urand(&seed, -2.5, -0.8)};
    const double v0 = urand(&seed, -0.8, -0.2), d = pow(10.0, urand(&seed, -12, -8)), T = 1.0;
    fesd_model m = {.nx = 2, .nsys = 1, .n_modes = nm, .n_switch = ns, .field = f_ramp, .sw = c_ramp, .user = &P2};
    for (int q = 0; q < nmeth; q++) {
      fesd_settings set;
      fesd_settings_default(&set);
      set.family = meth[q].fam;
      set.stages = meth[q].s;
      double xe[2][2];
      int ev[2], st[2];
      for (int side = 0; side < 2; side++) {
        const double x0[2] = {side ? d : -d, v0};
        st[side] = hd_integrate(&m, &set, 0, x0, NULL, T, 1, &R);
        ev[side] = R.n_ev;
        memcpy(xe[side], R.x_end, sizeof xe[side]);
      }
      starts++;
      const int bad = st[0] || st[1] || fabs(xe[0][0] - xe[1][0]) > 1e-6 * (1 + fabs(xe[1][0])) || ev[0] != ev[1];
      if (meth[q].s == 1) { /* implicit Euler: several discrete solutions O(h) apart (counted) */
        start_s1 += bad;
        continue;
      }
      if (bad && start_bad++ < 6)
        printf("  start %d %s s=%d: d %.1e v0 %.3f a %.3f: below %s %d events x(T) %.6f, above %s %d events x(T) "
               "%.6f\n",
               c, meth[q].fam == FESD_RK_RADAU_IIA ? "radau" : "lobatto3c", meth[q].s, d, v0, P2.a,
               fesd_status_name(st[0]), ev[0], xe[0][0], fesd_status_name(st[1]), ev[1], xe[1][0]);
    }
  }
  printf("starts within 1e-12..1e-8 of the surface, both sides, one step of 1: %d pairs, %d differ (s >= 2; "
         "Radau s = 1: %d of 40)\n",
         starts, start_bad, start_s1);
  HD_CHECK(start_bad == 0, "%d of %d start pairs differ", start_bad, starts);
  HD_CHECK(cases >= 2000, "only %d cases", cases);
  HD_CHECK(unflagged == 0, "%d unflagged FESD_OK runs with another event sequence than the flow's", unflagged);
  HD_CHECK(wrong_state == 0, "%d FESD_OK runs with x(T) beyond the bound", wrong_state);
  HD_CHECK(failed <= cases / 50, "%d of %d runs failed", failed, cases);
  printf("%s (%d failures)\n", fails ? "FAIL" : "OK", fails);
  return fails ? 1 : 0;
}
