/* Work-precision: CPU time per integration against the error at T of
 *  - error-controlled FESD (fesd_integrate), Radau IIA s = 2..5, rtol = 1e-2 .. 1e-12
 *    (atol = rtol, the states are O(1)); its front over s;
 *  - fixed-step FESD, Radau IIA s = 1..5, N_FE = 2, N_sim doubling from 5 (the best a user
 *    who tunes s and N_sim by hand gets: the front over all of them);
 *  - SUNDIALS CVODE (when built with it), Adams (fixed-point iteration) and BDF (dense
 *    Newton), rtol = 1e-2 .. 1e-12, atol = 1e-2 rtol: the right-hand side takes the mode of
 *    the side the state is on (sign of the switching function), and root finding on the
 *    switching function restarts the integration at each sign change: exact at crossings; on
 *    a sliding surface a chattering sequence of roots (the classical way without a Filippov
 *    formulation; at most CV_MAX_ROOTS roots, then the run counts as failed).
 * Problems with one switching function and an exact solution: oscillator (a crossing),
 * sign-c (sliding, then an exit), slide-exit-2d (curved sliding surface, exit), stick-slip.
 * Summary per problem (workprec_summary.csv): CPU ratio at equal error of adaptive FESD to
 * the fixed-step front and of CVODE Adams / BDF to adaptive FESD (geometric mean, min and
 * max over log-spaced errors in the range both reach; for CVODE also restricted to errors
 * below 1e-6). Targets (issue: error control): adaptive / fixed <= 1.5 and Adams / adaptive
 * >= 2 below 1e-6 on the oscillator. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "bench_util.h"

#ifdef HAVE_CVODE
#include <cvode/cvode.h>
#include <nvector/nvector_serial.h>
#include <sunlinsol/sunlinsol_dense.h>
#include <sunmatrix/sunmatrix_dense.h>
#include <sunnonlinsol/sunnonlinsol_fixedpoint.h>
#define CV_MAX_ROOTS 20000
#endif

#define MAXP 256

typedef struct {
  bench_point p[MAXP];
  int n;
} series;

static FILE *csv;

static void add(series *S, const char *prob, const char *method, int s, double param, double t, double e, int st,
                int steps) {
  if (S->n < MAXP) S->p[S->n] = (bench_point){st ? NAN : t, st ? NAN : e, S->n}, S->n++;
  fprintf(csv, "%s,%s,%d,%.3e,%.6e,%.6e,%d,%d\n", prob, method, s, param, 1e3 * t, e, steps, st);
  printf("  %-13s %-15s s=%d %-9.1e %9.4f ms  err %.2e  steps %6d%s\n", prob, method, s, param, 1e3 * t, e, steps,
         st ? "  FAILED" : "");
  fflush(stdout);
}

static double err_at_T(const fesd_problem *P, const double *x) {
  double xe[FESD_PROBLEM_MAX_NX], e = 0;
  P->exact(P->T, xe);
  for (int i = 0; i < P->model.nx; i++) e = fmax(e, fabs(x[i] - xe[i]));
  return e;
}

/* ---- error-controlled FESD ---- */
typedef struct {
  fesd_integrator *it;
  const fesd_problem *P;
} adaptive_job;

static int adaptive_fn(void *ctx) {
  adaptive_job *j = ctx;
  int st = fesd_set_state(j->it, 0.0, j->P->x0, j->P->u);
  return st ? st : fesd_integrate(j->it, j->P->u, j->P->T, NULL);
}

static void run_adaptive(const fesd_problem *P, series *S) {
  const int nt = bench_opt.quick ? 4 : 11;
  for (int s = 2; s <= 5; s++) {
    fesd_settings set;
    fesd_settings_default(&set);
    set.stages = s;
    fesd_integrator *it = bench_create(P, &set);
    if (!it) continue;
    for (int k = 0; k < nt; k++) {
      const double rtol = pow(10.0, -2.0 - k * (bench_opt.quick ? 3.0 : 1.0));
      fesd_tolerances tol;
      fesd_tolerances_default(&tol);
      tol.rtol = rtol, tol.atol = rtol;
      fesd_set_tolerances(it, &tol);
      adaptive_job j = {it, P};
      int st = adaptive_fn(&j);
      double x[FESD_PROBLEM_MAX_NX];
      fesd_get_state(it, NULL, x);
      fesd_stats stats;
      fesd_get_stats(it, &stats);
      double e = st ? NAN : err_at_T(P, x), t = st ? NAN : bench_time(adaptive_fn, &j);
      add(S, P->name, "fesd-adaptive", s, rtol, t, e, st, stats.steps);
    }
    fesd_free(&it);
  }
}

/* ---- fixed-step FESD ---- */
static void run_fixed(const fesd_problem *P, series *S) {
  const int ng = bench_opt.quick ? 3 : 8;
  for (int s = 1; s <= 5; s++) {
    fesd_settings set;
    fesd_settings_default(&set);
    set.stages = s;
    fesd_integrator *it = bench_create(P, &set);
    if (!it) continue;
    for (int g = 0; g < ng; g++) {
      bench_job j = {it, P, 5 << g, P->T};
      bench_run r;
      int st = bench_integrate(&j, &r);
      double t = st ? NAN : bench_time(bench_integrate_fn, &j);
      add(S, P->name, "fesd-fixed", s, j.nsim, t, r.err, st, r.stats.steps);
      if (st || r.err < 1e-13) break;
    }
    fesd_free(&it);
  }
}

#ifdef HAVE_CVODE
/* ---- CVODE with root finding and mode flips ---- */
typedef struct {
  const fesd_problem *P;
  int mode, roots, flag; /* flag: CVODE's last return value (or CV_MAX_ROOTS exceeded: 1) */
  void *mem;
  N_Vector y;
  double rtol;
} cv_job;

static int cv_rhs(sunrealtype t, N_Vector y, N_Vector yd, void *ud) {
  cv_job *j = ud;
  const fesd_model *m = &j->P->model;
  double c, *x = N_VGetArrayPointer(y);
  if (m->sw(0, t, x, j->P->u, &c, m->user)) return -1;
  const int mode = c > 0 ? 0 : c < 0 ? 1 : j->mode; /* on the surface: the side last seen */
  return m->field(0, mode, t, x, j->P->u, N_VGetArrayPointer(yd), m->user);
}
static int cv_root(sunrealtype t, N_Vector y, sunrealtype *g, void *ud) {
  cv_job *j = ud;
  return j->P->model.sw(0, t, N_VGetArrayPointer(y), j->P->u, g, j->P->model.user);
}

static int cv_fn(void *ctx) {
  cv_job *j = ctx;
  const fesd_problem *P = j->P;
  double *y = N_VGetArrayPointer(j->y), c;
  memcpy(y, P->x0, (size_t)P->model.nx * sizeof(double));
  P->model.sw(0, 0.0, y, P->u, &c, P->model.user);
  j->mode = c > 0 ? 0 : c < 0 ? 1 : 0; /* on the surface: mode 0 (no Filippov choice) */
  j->roots = 0;
  if (CVodeReInit(j->mem, 0.0, j->y) != CV_SUCCESS) return 1;
  double t = 0;
  j->flag = 0;
  while (t < P->T) {
    int f = CVode(j->mem, P->T, j->y, &t, CV_NORMAL);
    if (f == CV_ROOT_RETURN) { /* a sign change: restart (the right-hand side jumps) */
      if (++j->roots > CV_MAX_ROOTS) return j->flag = 1;
      j->mode ^= 1;
      if ((f = CVodeReInit(j->mem, t, j->y)) != CV_SUCCESS) return j->flag = f;
      continue;
    }
    if (f < 0) return j->flag = f;
  }
  return 0;
}

static void run_cvode(const fesd_problem *P, int lmm, series *S) {
  SUNContext ctx;
  if (SUNContext_Create(NULL, &ctx)) return;
  const int nx = P->model.nx, nt = bench_opt.quick ? 4 : 11;
  cv_job j = {.P = P};
  j.y = N_VNew_Serial(nx, ctx);
  j.mem = CVodeCreate(lmm, ctx);
  SUNMatrix A = NULL;
  SUNLinearSolver LS = NULL;
  SUNNonlinearSolver NLS = NULL;
  memcpy(N_VGetArrayPointer(j.y), P->x0, (size_t)nx * sizeof(double));
  CVodeInit(j.mem, cv_rhs, 0.0, j.y);
  CVodeSetUserData(j.mem, &j);
  CVodeRootInit(j.mem, 1, cv_root);
  CVodeSetMaxNumSteps(j.mem, 1000000);
  if (lmm == CV_BDF) {
    A = SUNDenseMatrix(nx, nx, ctx);
    LS = SUNLinSol_Dense(j.y, A, ctx);
    CVodeSetLinearSolver(j.mem, LS, A); /* difference-quotient Jacobian */
  } else {
    NLS = SUNNonlinSol_FixedPoint(j.y, 0, ctx);
    CVodeSetNonlinearSolver(j.mem, NLS);
  }
  for (int k = 0; k < nt; k++) {
    j.rtol = pow(10.0, -2.0 - k * (bench_opt.quick ? 3.0 : 1.0));
    CVodeSStolerances(j.mem, j.rtol, 1e-2 * j.rtol);
    int st = cv_fn(&j);
    long steps = 0;
    CVodeGetNumSteps(j.mem, &steps);
    double e = st ? NAN : err_at_T(P, N_VGetArrayPointer(j.y)), t = st ? NAN : bench_time(cv_fn, &j);
    add(S, P->name, lmm == CV_BDF ? "cvode-bdf" : "cvode-adams", 0, j.rtol, t, e, st, (int)steps);
    if (st) { /* why it failed */
      char *name = j.flag == 1 ? NULL : CVodeGetReturnFlagName(j.flag);
      printf("      CVODE stopped: %s after %d roots\n", name ? name : "more than CV_MAX_ROOTS roots", j.roots);
      free(name);
    }
  }
  CVodeFree(&j.mem);
  if (NLS) SUNNonlinSolFree(NLS);
  if (LS) SUNLinSolFree(LS);
  if (A) SUNMatDestroy(A);
  N_VDestroy(j.y);
  SUNContext_Free(&ctx);
}
#endif

#ifdef HAVE_CVODE
/* ---- paired rounds against CVODE Adams at an error target, full cost of each run ---- */
typedef struct {
  const fesd_problem *P;
  int s, nsim;
} fixed_run;

/* FESD, fixed steps: create, integrate, free (setup included) */
static int fixed_full(void *ctx) {
  fixed_run *r = ctx;
  fesd_settings set;
  fesd_settings_default(&set);
  set.stages = r->s;
  fesd_integrator *it;
  if (fesd_create(&it, &r->P->model, &set)) return 1;
  bench_job j = {it, r->P, r->nsim, r->P->T};
  int st = bench_integrate(&j, NULL);
  fesd_free(&it);
  return st;
}

typedef struct {
  const fesd_problem *P;
  double rtol, err;
} adams_run;

/* CVODE Adams: context, vector, solver, integration, free (setup included) */
static int adams_full(void *ctx) {
  adams_run *a = ctx;
  SUNContext sc;
  if (SUNContext_Create(NULL, &sc)) return 1;
  cv_job j = {.P = a->P};
  j.y = N_VNew_Serial(a->P->model.nx, sc);
  j.mem = CVodeCreate(CV_ADAMS, sc);
  memcpy(N_VGetArrayPointer(j.y), a->P->x0, (size_t)a->P->model.nx * sizeof(double));
  CVodeInit(j.mem, cv_rhs, 0.0, j.y);
  CVodeSetUserData(j.mem, &j);
  CVodeRootInit(j.mem, 1, cv_root);
  CVodeSetMaxNumSteps(j.mem, 1000000);
  SUNNonlinearSolver NLS = SUNNonlinSol_FixedPoint(j.y, 0, sc);
  CVodeSetNonlinearSolver(j.mem, NLS);
  CVodeSStolerances(j.mem, a->rtol, 1e-2 * a->rtol);
  int st = cv_fn(&j);
  a->err = st ? NAN : err_at_T(a->P, N_VGetArrayPointer(j.y));
  CVodeFree(&j.mem);
  SUNNonlinSolFree(NLS);
  N_VDestroy(j.y);
  SUNContext_Free(&sc);
  return st;
}

/* The cheapest fixed-step FESD run (s = 2..5, N_sim = 5 2^g) and the cheapest CVODE Adams run
 * (rtol = 10^(-k/4)) that reach error <= E, then their CPU ratio in paired rounds. */
static void pair_at(FILE *out, const fesd_problem *P, double E) {
  fixed_run best_f = {P, 0, 0};
  adams_run best_a = {P, 0, 0};
  double tf = INFINITY, ta = INFINITY;
  for (int s = 2; s <= 5; s++)
    for (int g = 0; g < 8; g++) {
      fixed_run r = {P, s, 5 << g};
      fesd_settings set;
      fesd_settings_default(&set);
      set.stages = s;
      fesd_integrator *it = bench_create(P, &set);
      bench_run br;
      bench_job j = {it, P, r.nsim, P->T};
      int st = it ? bench_integrate(&j, &br) : 1;
      fesd_free(&it);
      if (st || !(br.err <= E)) continue;
      const double t = bench_time(fixed_full, &r);
      if (t < tf) tf = t, best_f = r;
      break; /* more steps cost more */
    }
  for (int k = 8; k <= 56; k++) {
    adams_run a = {P, pow(10.0, -k / 4.0), NAN};
    if (adams_full(&a) || !(a.err <= E)) continue;
    const double t = bench_time(adams_full, &a);
    if (t < ta) ta = t, best_a = a;
    break; /* tighter tolerances cost more */
  }
  if (!best_f.s || !(best_a.rtol > 0)) {
    printf("%s: error %.0e not reached (FESD s=%d, CVODE rtol %.1e)\n", P->name, E, best_f.s, best_a.rtol);
    return;
  }
  double t1, t2;
  const double ratio = bench_time_pair(adams_full, &best_a, fixed_full, &best_f, &t1, &t2);
  fprintf(out, "%s,%.0e,%d,%d,%.3e,%.2f,%.2f,%.3f\n", P->name, E, best_f.s, best_f.nsim, best_a.rtol, 1e6 * t2,
          1e6 * t1, ratio);
  printf("%s error <= %.0e: FESD s=%d N_sim=%d %.1f us, CVODE Adams rtol %.1e %.1f us: FESD / CVODE %.3f (paired)\n",
         P->name, E, best_f.s, best_f.nsim, 1e6 * t2, best_a.rtol, 1e6 * t1, ratio);
  fflush(stdout);
}

static int pair_mode(void) {
  FILE *out = bench_csv("cvode_pair.csv", "problem,error_max,fesd_s,fesd_nsim,cvode_rtol,fesd_us,cvode_us,"
                                          "ratio_fesd_to_cvode");
  if (!out) return 1;
  fesd_problem P;
  fesd_problem_get("oscillator", &P);
  pair_at(out, &P, 1e-10);
  pair_at(out, &P, 1e-6);
  fclose(out);
  return 0;
}
#endif

static FILE *summary;

/* CPU ratio time_num(E) / time_den(E) at equal error E over the errors both fronts reach
 * (log-spaced; only E < e_max); writes a summary row. */
static void ratio(const char *prob, const char *what, const series *num, const series *den, double e_max,
                  const char *target) {
  bench_point A[MAXP], B[MAXP];
  int ka = bench_front(num->p, num->n, A), kb = bench_front(den->p, den->n, B);
  double lsum = 0, rmin = INFINITY, rmax = 0;
  int m = 0;
  if (ka && kb) {
    double hi = fmin(fmin(A[0].e, B[0].e), e_max), lo = fmax(A[ka - 1].e, B[kb - 1].e);
    for (int i = 0; i <= 40 && lo <= hi; i++) {
      double E = hi * pow(lo / hi, i / 40.0), r = bench_front_time(A, ka, E) / bench_front_time(B, kb, E);
      if (!isfinite(r)) continue;
      lsum += log(r), rmin = fmin(rmin, r), rmax = fmax(rmax, r), m++;
    }
  }
  double gm = m ? exp(lsum / m) : NAN;
  fprintf(summary, "%s,%s,%.3e,%.3f,%.3f,%.3f,%d,%s\n", prob, what, e_max, gm, m ? rmin : NAN, m ? rmax : NAN, m,
          target);
  printf("%-13s %-26s errors < %.0e: CPU ratio at equal error %.2f (range %.2f .. %.2f, %d samples)%s%s\n", prob,
         what, e_max, gm, m ? rmin : NAN, m ? rmax : NAN, m, *target ? "  target " : "", target);
}

int main(int argc, char **argv) {
#ifdef HAVE_CVODE
  /* --pair [OUTDIR]: only the paired-rounds comparison with CVODE Adams (cvode_pair.csv) */
  if (argc >= 2 && !strcmp(argv[1], "--pair")) {
    argv[1] = argv[0];
    return bench_init(argc - 1, argv + 1, "bench_workprec --pair [OUTDIR]") ? 1 : pair_mode();
  }
#endif
  if (bench_init(argc, argv, "bench_workprec [--quick] [OUTDIR]")) return 1;
  csv = bench_csv("workprec.csv", "problem,method,stages,param,cpu_ms,error,steps,status");
  summary = bench_csv("workprec_summary.csv", "problem,comparison,error_below,ratio_gmean,ratio_min,ratio_max,"
                                              "samples,target");
  if (!csv || !summary) return 1;
  const char *probs[] = {"oscillator", "sign-c", "slide-exit-2d", "stick-slip"};
  for (int q = 0; q < 4; q++) {
    fesd_problem P;
    fesd_problem_get(probs[q], &P);
    static series ad, fx, ca, cb;
    ad.n = fx.n = ca.n = cb.n = 0;
    run_adaptive(&P, &ad);
    run_fixed(&P, &fx);
    const int osc = q == 0;
    ratio(P.name, "adaptive / best fixed", &ad, &fx, INFINITY, osc ? "<= 1.5" : "");
#ifdef HAVE_CVODE
    run_cvode(&P, CV_ADAMS, &ca);
    run_cvode(&P, CV_BDF, &cb);
    ratio(P.name, "cvode-adams / adaptive", &ca, &ad, 1e-6, osc ? ">= 2" : "");
    ratio(P.name, "cvode-bdf / adaptive", &cb, &ad, 1e-6, "");
#endif
  }
  fclose(csv);
  fclose(summary);
  return 0;
}
