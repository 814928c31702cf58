/* Sensitivities are never silently wrong (property test).
 *
 * A run is silently wrong when it returns FESD_OK, no step set FESD_FLAG_SENS_INACCURATE (nor
 * FESD_FLAG_COARSE: a step too long for its accuracy, whose state and sensitivities are both
 * only as good as that error), and
 * dx(T)/dx0 or dx(T)/du differs from
 *  - central differences of the FESD map itself (the same settings from x0 +- eps e_j and
 *    u +- eps e_j, eps = 1e-6 max(1, |v_j|)) by more than 1e-5 max(1, |S|) (per column). Skipped where the map is not
 *    differentiable: a perturbed run fails or its event sequence differs, or (checked only when
 *    a column disagrees) the differences with eps / 10 and 10 eps spread by more than a third of
 *    S's distance to the nearest of them: the map is not smooth at this scale (it jumps between
 *    nearby discrete solutions with the same events), so the column is skipped (a run whose other
 *    columns agree counts as a jump);
 *  - the closed form where there is one: piecewise-constant fields (FESD is exact, so its map
 *    is the exact flow; sensitivities of the reference pwa_ref.c: saltation matrices at
 *    crossings and entries) by more than 1e-5 max(1, |S|), and the reproducer below
 *    by more than 1e-7.
 * For piecewise-constant fields the state must also be exact (events and x(T) to 1e-9) unless a
 * flag admits an inaccurate state (EXIT_NOT_PINNED, NONUNIQUE, COARSE).
 * Runs: 112 random problems (pwa_random_system; controls u, nu = 1..2, enter the fields through
 * B) of seven kinds: piecewise-constant crossings, sliding, several subsystems sliding (a surface
 * reached while another subsystem slides), an event exactly on the step grid (T = t_e N_sim / k);
 * affine crossings, sliding exits, several sliding. 1750 runs with random family (Radau IIA,
 * Lobatto IIIC, Gauss-Legendre; not Gauss on the kinds with exits, which it cannot pin),
 * s = 2..5, N_sim = 2..40 (log-uniform), N_FE = 2..3, exact or finite-difference Jacobians;
 * plus the reproducer (312 runs):
 *   (x1, x2, q): x1' in -sign(x1) + 0.3, x2' in -sign(x2) - 0.2, q' = x2, x(0) = (10, -1, 0),
 *   T = 3: x1 never switches, x2 reaches 0 at t_s = 1.25 and slides, q(T) = -0.625 x2(0)^2
 *   (x2(0) < 0), so dq(T)/dx2(0) = t_s = 1.25, dx2(T)/dx2(0) = 0, dx1(T)/dx1(0) = 1;
 *   and its variant x1(0) = 1 (x1 reaches 0 at 1/0.7 and slides too: dx1(T)/dx1(0) = 0);
 *   Radau IIA, N_FE = 2, finite-difference Jacobians, s = 2..5, N_sim = 2..40 each.
 * Asserts zero silently wrong runs; prints the counts and the worst agreements.
 * --reproducer / --shard K N: parts (tests/prop/meson.build); --probe: one run in detail. */
#include <stdlib.h>

#include "prop_util.h"

#define N_PER_KIND 16

typedef struct {
  pwa_sys S;
  double x0[PWA_MAX_NX], u[PWA_MAX_NU], T;
  pwa_result ref;
  int kind, exact, nsim; /* exact: FESD reproduces the flow (piecewise constant); nsim > 0: fixed */
  int index;
} problem;

static const pr_category KINDS[] = {
    /* name, affine, K, nx, nu, slide_prob, a_scale, rot, min_ev, entry, exit, multi */
    {"constant, crossings", 0, 1, 3, 2, 3, 1, 2, 0.0, 0, 0, 3, -1, -1, -1},
    {"constant, sliding", 0, 1, 3, 2, 3, 1, 2, 0.6, 0, 0, 2, 1, -1, -1},
    {"constant, several sliding", 0, 2, 3, 2, 3, 1, 2, 0.6, 0, 0, 2, 1, -1, 1},
    {"affine, crossings", 1, 1, 3, 2, 3, 1, 2, 0.0, 0.3, 2, 3, -1, -1, -1},
    {"affine, exits", 1, 1, 3, 2, 3, 1, 2, 0.6, 0.6, 3, 2, 1, 1, -1},
    {"affine, several sliding", 1, 2, 3, 2, 3, 1, 2, 0.6, 0.6, 3, 2, 1, 0, 1},
};
#define N_KINDS ((int)(sizeof(KINDS) / sizeof(KINDS[0])))
#define KIND_GRID N_KINDS /* constant fields, an event exactly on the step grid */
/* runs per kind (1750 in all), fewer on the kinds whose runs cost most */
static const int RUNS_PER_KIND[N_KINDS + 1] = {330, 200, 160, 300, 300, 160, 300};

typedef struct {
  int runs, ok, failed, flagged, fd_cmp, fd_skip, cf_cmp, silent, primal_wrong, jumps;
  double worst_fd, worst_cf;    /* unflagged runs */
  double worst_fd_flagged;
} tally;

static double col_err(int nx, const double *S, const double *R, double *scale_out) {
  /* max over rows of |S - R| / max(1, max |S| of the column) */
  double sc = 1, e = 0;
  for (int i = 0; i < nx; i++) sc = fmax(sc, fabs(S[i]));
  for (int i = 0; i < nx; i++) e = fmax(e, fabs(S[i] - R[i]));
  if (scale_out) *scale_out = sc;
  return e / sc;
}

/* One run with sensitivities and its checks. */
static int check_run(const problem *P, const fesd_settings *set, int jac, tally *ta, int verbose) {
  int fails = 0;
  const pwa_sys *S = &P->S;
  const int nx = S->nx, nu = S->nu, nsim = P->nsim;
  pr_model pm;
  pr_model_init(&pm, S, jac);
  static pr_run r, rp, rm;
  fesd_integrator *it;
  ta->runs++;
  if (fesd_create(&it, &pm.m, set)) {
    ta->failed++;
    FESD_TEST_CHECK(0, "fesd_create failed");
    return fails;
  }
  /* the perturbed runs below restart the same integrator (the same settings; sensitivities on:
   * in rare cases they change the discrete solution a step returns,
   * prop_known_sens_changes_state) */
  const int st = pr_run_on(it, &pm.m, 1, P->x0, P->u, P->T, nsim, &r);
  if (st) {
    ta->failed++;
    fesd_free(&it);
    return 0;
  }
  ta->ok++;
  const int flagged = (r.flags & (FESD_FLAG_SENS_INACCURATE | FESD_FLAG_COARSE)) != 0;
  ta->flagged += flagged;
  /* central differences of the FESD map, column by column; where one disagrees with S, the
   * differences with eps / 10 and 10 eps decide: if they agree with it the map is smooth and S
   * is wrong; if not, the map is not smooth at this scale (it jumps between nearby discrete
   * solutions with the same events) and the column is skipped, counted as a jump */
  double fd_err = 0;
  int fd_done = 1, jump = 0;
  for (int j = 0; j < nx + nu && fd_done; j++) {
    const double *Sj = j < nx ? r.Sx + j * nx : r.Su + (j - nx) * nx;
    double fd[3][PWA_MAX_NX], e[3];
    const double base = j < nx ? P->x0[j] : P->u[j - nx], mult[3] = {1, 0.1, 10};
    int nd = 0;
    for (int q = 0; q < 3; q++) {
      double xp[PWA_MAX_NX], xm[PWA_MAX_NX], up[PWA_MAX_NU], um[PWA_MAX_NU];
      memcpy(xp, P->x0, sizeof(xp)), memcpy(xm, P->x0, sizeof(xm));
      memcpy(up, P->u, sizeof(up)), memcpy(um, P->u, sizeof(um));
      const double eps = 1e-6 * mult[q] * fmax(1, fabs(base));
      if (j < nx) xp[j] += eps, xm[j] -= eps;
      else up[j - nx] += eps, um[j - nx] -= eps;
      if (pr_run_on(it, &pm.m, 0, xp, up, P->T, nsim, &rp) || pr_run_on(it, &pm.m, 0, xm, um, P->T, nsim, &rm) ||
          !pr_same_run_events(&r, &rp) || !pr_same_run_events(&r, &rm))
        break;
      for (int i = 0; i < nx; i++) fd[q][i] = (rp.x[i] - rm.x[i]) / (2 * eps);
      e[q] = col_err(nx, Sj, fd[q], NULL);
      nd++;
      if (q == 0 && e[0] <= 1e-5) break;
    }
    if (nd == 0) {
      fd_done = 0; /* the events change: not differentiable */
    } else if (nd == 1) {
      fd_err = fmax(fd_err, e[0]);
    } else {
      double spread = 0, emin = INFINITY;
      for (int a = 0; a < nd; a++) {
        emin = fmin(emin, e[a]);
        for (int b = 0; b < a; b++) spread = fmax(spread, col_err(nx, fd[a], fd[b], NULL));
      }
      if ((nd == 3 && spread <= 1e-5) || emin > 3 * spread)
        fd_err = fmax(fd_err, emin); /* smooth, or S farther from every quotient than they spread */
      else
        jump = 1;
    }
  }
  if (jump && fd_done && fd_err <= 1e-5) { /* nothing wrong where the map is smooth */
    fd_done = 0;
    ta->jumps++;
    if (ta->jumps <= 2)
      printf("note: the map jumps (differences with eps 1e-7, 1e-6, 1e-5 disagree, same events): problem %d (%s), "
             "%s s=%d N_sim=%d N_FE=%d, flags 0x%x\n",
             P->index, P->kind < N_KINDS ? KINDS[P->kind].name : "grid", fesd_rk_family_name(set->family), set->stages,
             nsim, set->n_fe, r.flags);
  }
  fesd_free(&it);
  if (fd_done) {
    ta->fd_cmp++;
    if (flagged) ta->worst_fd_flagged = fmax(ta->worst_fd_flagged, fd_err);
    else ta->worst_fd = fmax(ta->worst_fd, fd_err);
  } else if (!jump) {
    ta->fd_skip++;
  }
  /* closed form (piecewise-constant fields) */
  double cf_err = 0;
  int cf_done = 0;
  if (P->exact) {
    double dt;
    double xe = 0;
    for (int i = 0; i < nx; i++) xe = fmax(xe, fabs(r.x[i] - P->ref.x[i]) / fmax(1, fabs(P->ref.x[i])));
    /* flags that admit an inaccurate state; SENS_INACCURATE says the state is to be trusted */
    const int state_flagged = (r.flags & (FESD_FLAG_EXIT_NOT_PINNED | FESD_FLAG_NONUNIQUE | FESD_FLAG_COARSE)) != 0;
    if (!pr_same_events(&r, &P->ref, &dt) || xe > 1e-9) {
      ta->primal_wrong += !state_flagged;
      FESD_TEST_CHECK(state_flagged,
                      "problem %d (%s): FESD_OK, events %d (reference %d), x(T) error %.1e, flags 0x%x (%s s=%d N_sim=%d "
                      "N_FE=%d): piecewise-constant fields are integrated exactly",
                      P->index, P->kind < N_KINDS ? KINDS[P->kind].name : "grid", r.n_ev, P->ref.n_ev, xe, r.flags,
                      fesd_rk_family_name(set->family), set->stages, nsim, set->n_fe);
    } else {
      cf_done = 1;
      for (int j = 0; j < nx + nu; j++) {
        double col[PWA_MAX_NX];
        for (int i = 0; i < nx; i++) col[i] = j < nx ? P->ref.Sx[i][j] : P->ref.Su[i][j - nx];
        cf_err = fmax(cf_err, col_err(nx, j < nx ? r.Sx + j * nx : r.Su + (j - nx) * nx, col, NULL));
      }
      ta->cf_cmp++;
      if (!flagged) ta->worst_cf = fmax(ta->worst_cf, cf_err);
    }
  }
  const int wrong = (fd_done && fd_err > 1e-5) || (cf_done && cf_err > 1e-5);
  if (wrong && !flagged) {
    ta->silent++;
    FESD_TEST_CHECK(0, "silently wrong: problem %d (%s), %s s=%d N_sim=%d N_FE=%d %s Jacobians: vs differences %.2e%s, vs closed form %.2e%s",
                    P->index, P->kind < N_KINDS ? KINDS[P->kind].name : "event on the step grid", fesd_rk_family_name(set->family),
                    set->stages, nsim, set->n_fe, jac ? "exact" : "FD", fd_err, fd_done ? "" : " (skipped)", cf_err,
                    cf_done ? "" : " (none)");
    if (verbose) {
      pr_print_system(S, P->x0, P->u);
      printf("   T = %.17g\n", P->T);
      pr_print_events_ref(&P->ref);
    }
  }
  return fails;
}

/* The reproducer: state (x1, x2, q). */
static int rep_field(int sys, int mode, double t, const double *x, const double *u, double *f, void *user) {
  (void)t, (void)u, (void)user;
  const double sg = mode == 0 ? -1.0 : 1.0; /* -sign(c): mode 0 is c > 0 */
  f[0] = sys == 0 ? sg + 0.3 : 0;
  f[1] = sys == 1 ? sg - 0.2 : 0;
  f[2] = sys == 1 ? x[1] : 0; /* q' = x2, carried by subsystem 1 in both modes */
  return 0;
}
static int rep_switch(int sys, double t, const double *x, const double *u, double *c, void *user) {
  (void)t, (void)u, (void)user;
  c[0] = x[sys];
  return 0;
}

static int reproducer(tally *ta) {
  int fails = 0;
  const int nm[2] = {2, 2}, ns[2] = {1, 1};
  const fesd_model m = {.nx = 3, .nsys = 2, .n_modes = nm, .n_switch = ns, .field = rep_field, .sw = rep_switch};
  for (int v = 0; v < 2; v++) {
    const double x0[3] = {v ? 1.0 : 10.0, -1.0, 0.0};
    /* row-major closed form: x1 = x1(0) - 0.7 t until it slides (variant 1) */
    const double Se[3][3] = {{v ? 0.0 : 1.0, 0, 0}, {0, 0, 0}, {0, 1.25, 1}};
    int ok = 0, flagged = 0, bad = 0, failed = 0, fd_skip = 0;
    double worst = 0, worst_fd = 0;
    for (int s = 2; s <= 5; s++)
      for (int nsim = 2; nsim <= 40; nsim++) {
        fesd_settings set;
        fesd_settings_default(&set);
        set.stages = s;
        set.sensitivities = 1;
        static pr_run r, rp, rm;
        ta->runs++;
        if (pr_integrate(&m, &set, x0, NULL, 3.0, nsim, &r)) {
          failed++, ta->failed++;
          continue;
        }
        ta->ok++;
        const int fl = (r.flags & FESD_FLAG_SENS_INACCURATE) != 0;
        double e = 0, efd = 0;
        for (int i = 0; i < 3; i++)
          for (int j = 0; j < 3; j++) e = fmax(e, fabs(r.Sx[j * 3 + i] - Se[i][j]));
        /* and the differences of the map (x2(0) +- eps moves t_s across step boundaries when
         * N_sim is a multiple of 12: the map stays differentiable) */
        int fd_ok = 1;
        for (int j = 0; j < 3 && fd_ok; j++) {
          double xp[3] = {x0[0], x0[1], x0[2]}, xm[3] = {x0[0], x0[1], x0[2]};
          const double eps = 1e-6 * fmax(1, fabs(x0[j]));
          xp[j] += eps, xm[j] -= eps;
          fd_ok = !pr_integrate(&m, &set, xp, NULL, 3.0, nsim, &rp) && !pr_integrate(&m, &set, xm, NULL, 3.0, nsim, &rm) &&
                  pr_same_run_events(&r, &rp) && pr_same_run_events(&r, &rm);
          for (int i = 0; i < 3 && fd_ok; i++)
            efd = fmax(efd, fabs(r.Sx[j * 3 + i] - (rp.x[i] - rm.x[i]) / (2 * eps)) / fmax(1, fabs(r.Sx[j * 3 + i])));
        }
        if (fd_ok) ta->fd_cmp++;
        else fd_skip++, ta->fd_skip++;
        ta->cf_cmp++;
        flagged += fl, ta->flagged += fl;
        if ((e > 1e-7 || (fd_ok && efd > 1e-5)) && !fl) {
          bad++, ta->silent++;
          FESD_TEST_CHECK(0, "reproducer x1(0)=%g s=%d N_sim=%d: dx(T)/dx0 error %.2e (dq/dx2 %.12f, dx2/dx2 %.3e), "
                          "vs differences %.2e, not flagged",
                          x0[0], s, nsim, e, r.Sx[1 * 3 + 2], r.Sx[1 * 3 + 1], efd);
        } else if (!fl) {
          ok++;
          worst = fmax(worst, e), worst_fd = fmax(worst_fd, fd_ok ? efd : 0);
        }
      }
    ta->worst_cf = fmax(ta->worst_cf, worst);
    printf("reproducer x1(0) = %g (%s): %d runs (Radau IIA s=2..5, N_sim=2..40), %d match the closed form to 1e-7 "
           "(worst %.1e; vs differences %.1e, %d skipped), %d flagged, %d failed, %d silently wrong\n",
           x0[0], v ? "two sliding subsystems" : "one sliding subsystem", 4 * 39, ok, worst, worst_fd, fd_skip, flagged,
           failed, bad);
  }
  return fails;
}

/* An event of a piecewise-constant system exactly on the step grid: T = t_e N_sim / k. */
static int grid_problem(pwa_rng *rng, problem *P) {
  static const pr_category base = {"grid", 0, 1, 3, 2, 3, 1, 2, 0.4, 0, 0, 2, 0, -1, -1};
  for (int tries = 0; tries < 1000; tries++) {
    if (!pr_draw(rng, &base, 2.0, 1, 20000, &P->S, P->x0, P->u, &P->ref)) return 0;
    const int e = pwa_int(rng, 0, P->ref.n_ev - 1), nsim = pwa_int(rng, 2, 40);
    const double te = P->ref.ev[e].t;
    const int k = (int)ceil(te * nsim / 2.5); /* T = te nsim / k in [te, 2.5] */
    if (k < 1 || k >= nsim) continue;
    P->T = te * nsim / k;
    pwa_opts o;
    pwa_opts_default(&o, P->T);
    o.sens = 1;
    if (P->T < 1.0 || pwa_reference(&P->S, P->x0, P->u, &o, &P->ref)) continue;
    P->nsim = nsim;
    return 1;
  }
  return 0;
}

static problem probs[(N_KINDS + 1) * N_PER_KIND];

/* the random problems (fixed seed); returns their number */
static int make_problems(int *draws_out, int *fails_out) {
  int np = 0, draws = 0, fails = 0;
  for (int c = 0; c <= N_KINDS; c++) {
    pwa_rng rng_kind = {31337 + pr_seed_off() + 100 * (uint64_t)c}, *rng = &rng_kind;
    for (int i = 0; i < N_PER_KIND; i++) {
      problem *P = &probs[np];
      memset(P, 0, sizeof(*P));
      P->kind = c;
      int d;
      if (c == KIND_GRID) {
        d = grid_problem(rng, P);
      } else {
        P->T = 2.0;
        d = pr_draw(rng, &KINDS[c], P->T, 1, 20000, &P->S, P->x0, P->u, &P->ref);
      }
      FESD_TEST_CHECK(d > 0, "no system of kind %d found", c);
      if (!d) continue;
      draws += d;
      P->exact = c == KIND_GRID || !KINDS[c].affine;
      P->index = np++;
    }
  }
  *draws_out = draws;
  *fails_out += fails;
  return np;
}

/* --probe PROBLEM FAMILY S N_SIM N_FE JAC: one run, its sensitivities against central differences
 * of the map with eps = 1e-3 .. 1e-9 (a derivative that the differences converge to, or a jump
 * of the map: differences growing like 1/eps) */
static int probe(int argc, char **argv) {
  int draws, fails = 0;
  const int np = make_problems(&draws, &fails);
  const int pi = atoi(argv[2]);
  if (argc < 8 || pi < 0 || pi >= np) return 2;
  problem *P = &probs[pi];
  fesd_settings set;
  fesd_settings_default(&set);
  set.family = (fesd_rk_family)atoi(argv[3]);
  set.stages = atoi(argv[4]);
  P->nsim = atoi(argv[5]);
  set.n_fe = atoi(argv[6]);
  set.sensitivities = 1;
  pr_model pm;
  pr_model_init(&pm, &P->S, atoi(argv[7]));
  pr_print_system(&P->S, P->x0, P->u);
  printf("   T = %.17g, %s s=%d N_sim=%d N_FE=%d\n", P->T, fesd_rk_family_name(set.family), set.stages, P->nsim, set.n_fe);
  pr_print_events_ref(&P->ref);
  static pr_run r, rp, rm;
  int st = pr_integrate(&pm.m, &set, P->x0, P->u, P->T, P->nsim, &r);
  printf("status %s flags 0x%x\n", fesd_status_name(st), r.flags);
  pr_print_events_run(&r);
  const int nx = P->S.nx, nu = P->S.nu;
  for (int j = 0; j < nx + nu; j++) {
    printf("column %d: S =", j);
    for (int i = 0; i < nx; i++) printf(" %.9f", j < nx ? r.Sx[j * nx + i] : r.Su[(j - nx) * nx + i]);
    if (P->exact) {
      printf("  closed form =");
      for (int i = 0; i < nx; i++) printf(" %.9f", j < nx ? P->ref.Sx[i][j] : P->ref.Su[i][j - nx]);
    }
    printf("\n");
    for (double eps = 1e-3; eps >= 1e-9; eps /= 10) {
      double xp[PWA_MAX_NX], xm[PWA_MAX_NX], up[PWA_MAX_NU], um[PWA_MAX_NU];
      memcpy(xp, P->x0, sizeof(xp)), memcpy(xm, P->x0, sizeof(xm)), memcpy(up, P->u, sizeof(up)), memcpy(um, P->u, sizeof(um));
      if (j < nx) xp[j] += eps, xm[j] -= eps;
      else up[j - nx] += eps, um[j - nx] -= eps;
      const int a = pr_integrate(&pm.m, &set, xp, up, P->T, P->nsim, &rp), b = pr_integrate(&pm.m, &set, xm, um, P->T, P->nsim, &rm);
      printf("   eps %.0e: %s%s events %d/%d/%d, FD =", eps, a ? "FAIL " : "", b ? "FAIL " : "", rm.n_ev, r.n_ev, rp.n_ev);
      for (int i = 0; i < nx; i++) printf(" %.9f", (rp.x[i] - rm.x[i]) / (2 * eps));
      printf("\n");
    }
  }
  return 0;
}

int main(int argc, char **argv) {
  if (argc > 1 && !strcmp(argv[1], "--probe")) return probe(argc, argv);
  /* --reproducer: the reproducer only; --shard K N: the random runs with index K mod N
   * (registered in shards to keep each test under ~10 s); no argument: everything */
  int only_rep = 0, shard = 0, n_shards = 1;
  for (int a = 1; a < argc; a++) {
    if (!strcmp(argv[a], "--reproducer")) only_rep = 1;
    else if (!strcmp(argv[a], "--shard") && a + 2 < argc) shard = atoi(argv[a + 1]), n_shards = atoi(argv[a + 2]), a += 2;
  }
  int fails = 0;
  tally ta = {0};
  if (only_rep || n_shards == 1) fails += reproducer(&ta);
  const int rep_runs = ta.runs;
  if (only_rep) {
    printf("%d failures\n", fails);
    return fails != 0;
  }
  int draws;
  const int np = make_problems(&draws, &fails);
  int ev_total = 0, entries = 0, exits = 0, multi = 0;
  for (int i = 0; i < np; i++)
    ev_total += probs[i].ref.n_ev, entries += probs[i].ref.n_entry, exits += probs[i].ref.n_exit,
        multi += probs[i].ref.n_entry_multi + probs[i].ref.n_cross_multi;
  printf("%d random problems (%d draws): %d reference events, %d sliding entries, %d exits, %d surfaces reached while "
         "another subsystem slides\n",
         np, draws, ev_total, entries, exits, multi);
  tally kt[N_KINDS + 1];
  memset(kt, 0, sizeof(kt));
  const fesd_rk_family fams[3] = {FESD_RK_RADAU_IIA, FESD_RK_LOBATTO_IIIC, FESD_RK_GAUSS_LEGENDRE};
  pwa_rng rng = {4711 + pr_seed_off()}; /* the settings of every run, the same in every shard */
  int run = 0;
  for (int c = 0; c <= N_KINDS; c++)
    for (int i = 0; i < RUNS_PER_KIND[c]; i++, run++) {
      problem *P = NULL;
      for (int q = 0, seen = 0; q < np && !P; q++)
        if (probs[q].kind == c && seen++ == i % N_PER_KIND) P = &probs[q];
      fesd_settings set;
      fesd_settings_default(&set);
      /* Gauss-Legendre cannot pin sliding exits (FESD_FLAG_EXIT_NOT_PINNED, O(h) exit times):
       * not on the kinds with exits */
      const int with_exits = c < N_KINDS && KINDS[c].affine && KINDS[c].entry > 0;
      set.family = fams[pwa_int(&rng, 0, with_exits ? 1 : 2)];
      set.stages = pwa_int(&rng, 2, 5);
      set.n_fe = pwa_int(&rng, 2, 3);
      set.sensitivities = 1;
      /* N_sim log-uniform in 2..40: short and long steps alike, fewer steps in total */
      const int nsim = (int)lround(2 * pow(20.0, pwa_uniform(&rng, 0, 1)));
      const int jac = pwa_int(&rng, 0, 1);
      if (!P || run % n_shards != shard) continue;
      const int nsim_saved = P->nsim;
      if (c != KIND_GRID) P->nsim = nsim;
      fails += check_run(P, &set, jac, &kt[c], kt[c].silent < 3);
      P->nsim = nsim_saved;
    }
  for (int c = 0; c <= N_KINDS; c++) {
    const tally *k = &kt[c];
    printf("%-27s: %4d runs, %4d ok, %3d failed, %3d flagged, %4d vs differences (%3d skipped, %3d jumps), %4d vs "
           "closed form, %d silently wrong; worst unflagged: differences %.1e, closed form %.1e\n",
           c < N_KINDS ? KINDS[c].name : "constant, event on the grid", k->runs, k->ok, k->failed, k->flagged, k->fd_cmp,
           k->fd_skip, k->jumps, k->cf_cmp, k->silent, k->worst_fd, k->worst_cf);
    ta.runs += k->runs, ta.ok += k->ok, ta.failed += k->failed, ta.flagged += k->flagged, ta.fd_cmp += k->fd_cmp;
    ta.fd_skip += k->fd_skip, ta.cf_cmp += k->cf_cmp, ta.silent += k->silent, ta.primal_wrong += k->primal_wrong;
    ta.jumps += k->jumps;
    ta.worst_fd = fmax(ta.worst_fd, k->worst_fd), ta.worst_cf = fmax(ta.worst_cf, k->worst_cf);
  }
  printf("total: %d runs (%d reproducer), %d FESD_OK, %d failed with a status, %d flagged SENS_INACCURATE, %d compared "
         "with differences (%d skipped: events change; %d skipped: the map jumps), %d with the closed form; %d "
         "silently wrong, %d wrong states or events; worst unflagged agreement: differences %.1e, closed form %.1e\n",
         ta.runs, rep_runs, ta.ok, ta.failed, ta.flagged, ta.fd_cmp, ta.fd_skip, ta.jumps, ta.cf_cmp, ta.silent,
         ta.primal_wrong, ta.worst_fd, ta.worst_cf);
  if (n_shards == 1) FESD_TEST_CHECK(ta.runs >= 2000, "only %d runs", ta.runs);
  printf("%d failures\n", fails);
  return fails != 0;
}
