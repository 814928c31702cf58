/* Cost anatomy of an integration: time per step, Newton iterations and factorizations per
 * step, where the time goes, per linear-algebra backend, and how far one Newton iteration
 * is from the linear-algebra floor.
 *
 * Shares. The integrator reports only totals (fesd_get_stats), so this program is linked
 * with -Wl,--wrap=fesd_ncp_solve (and _solve_homotopy, _set_rows): every solve of the
 * integrator passes through a wrapper that accumulates the solver's own fesd_ncp_info
 * times (residual/Jacobian evaluation of the step system = model callbacks + assembly;
 * factorizations + solves; the rest of the solver: FB rows, line search). Shares are
 * these sums over the wall time of the same integrations; "outside" is the integrator's
 * own work (guess, sign checks, switch location, acceptance, row selection).
 * The model callbacks' share (of the CPU time): their calls are counted through a wrapping
 * model and multiplied by the CPU time of one call (timed alone).
 * Limit: one LAPACK dgetrf + dgetrs (with the copy of the matrix) of a dense random matrix
 * of the order of the step system (rows of the assembled system, fesd_ncp_rows); dense LU
 * costs the same whatever the zeros, so sparsity does not enter.
 * Output: anatomy.csv. */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "bench_util.h"

/* Fortran LAPACK (hidden length argument of character arguments, as src/common/lapack.h) */
void dgetrf_(const int *m, const int *n, double *a, const int *lda, int *ipiv, int *info);
void dgetrs_(const char *trans, const int *n, const int *nrhs, const double *a, const int *lda,
             const int *ipiv, double *b, const int *ldb, int *info, size_t trans_len);

/* ---- link-time wrappers of the solver entry points the integrator calls ---- */
int __real_fesd_ncp_solve(fesd_ncp *ws, double *z, double sigma, fesd_ncp_info *info);
int __real_fesd_ncp_solve_homotopy(fesd_ncp *ws, double *z, fesd_ncp_info *info);
int __real_fesd_ncp_set_rows(fesd_ncp *ws, const unsigned char *eq, const unsigned char *pm);
int __wrap_fesd_ncp_solve(fesd_ncp *ws, double *z, double sigma, fesd_ncp_info *info);
int __wrap_fesd_ncp_solve_homotopy(fesd_ncp *ws, double *z, fesd_ncp_info *info);
int __wrap_fesd_ncp_set_rows(fesd_ncp *ws, const unsigned char *eq, const unsigned char *pm);

static struct {
  double wall, total, eval, linsolve, set_rows, iter_time;
  long factorizations, solves, set_rows_calls, iterations;
  int max_rows;
} acc;

static double wall(void) {
  struct timespec t;
  clock_gettime(CLOCK_MONOTONIC, &t);
  return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

static void account(fesd_ncp *ws, const fesd_ncp_info *in) {
  acc.total += in->time_total;
  acc.eval += in->time_eval;
  acc.linsolve += in->time_linsolve;
  acc.factorizations += in->factorizations;
  acc.iter_time += in->time_iterations;
  acc.iterations += in->iterations;
  acc.solves++;
  int m = fesd_ncp_rows(ws);
  if (m > acc.max_rows) acc.max_rows = m;
}

int __wrap_fesd_ncp_solve(fesd_ncp *ws, double *z, double sigma, fesd_ncp_info *info) {
  fesd_ncp_info local;
  if (!info) info = &local;
  int rc = __real_fesd_ncp_solve(ws, z, sigma, info);
  account(ws, info);
  return rc;
}

int __wrap_fesd_ncp_solve_homotopy(fesd_ncp *ws, double *z, fesd_ncp_info *info) {
  fesd_ncp_info local;
  if (!info) info = &local;
  int rc = __real_fesd_ncp_solve_homotopy(ws, z, info);
  account(ws, info);
  return rc;
}

int __wrap_fesd_ncp_set_rows(fesd_ncp *ws, const unsigned char *eq, const unsigned char *pm) {
  double t0 = wall();
  int rc = __real_fesd_ncp_set_rows(ws, eq, pm);
  acc.set_rows += wall() - t0;
  acc.set_rows_calls++;
  return rc;
}

/* ---- model callbacks: counted through a wrapper, each kind timed alone ---- */
typedef struct {
  fesd_model m;
  long calls[4]; /* field, field_jac, sw, sw_jac */
} count_model;

static int c_field(int sys, int mode, double t, const double *x, const double *u, double *f, void *user) {
  count_model *w = user;
  w->calls[0]++;
  return w->m.field(sys, mode, t, x, u, f, w->m.user);
}
static int c_field_jac(int sys, int mode, double t, const double *x, const double *u, double *dx, double *du, void *user) {
  count_model *w = user;
  w->calls[1]++;
  return w->m.field_jac(sys, mode, t, x, u, dx, du, w->m.user);
}
static int c_sw(int sys, double t, const double *x, const double *u, double *c, void *user) {
  count_model *w = user;
  w->calls[2]++;
  return w->m.sw(sys, t, x, u, c, w->m.user);
}
static int c_sw_jac(int sys, double t, const double *x, const double *u, double *dx, double *du, void *user) {
  count_model *w = user;
  w->calls[3]++;
  return w->m.sw_jac(sys, t, x, u, dx, du, w->m.user);
}

typedef struct {
  const fesd_problem *P;
  int kind;
  double out[256], out_u[256];
} call_ctx;

static int call_loop(void *ctx) { /* 1000 calls of one callback kind at x0 (subsystem 0, mode 0) */
  call_ctx *c = ctx;
  const fesd_model *m = &c->P->model;
  const double *x = c->P->x0, *u = c->P->u;
  double *du = m->nu ? c->out_u : NULL;
  int rc = 0;
  for (int r = 0; r < 1000; r++) {
    if (c->kind == 0) rc |= m->field(0, 0, 0.0, x, u, c->out, m->user);
    else if (c->kind == 1) rc |= m->field_jac(0, 0, 0.0, x, u, c->out, du, m->user);
    else if (c->kind == 2) rc |= m->sw(0, 0.0, x, u, c->out, m->user);
    else rc |= m->sw_jac(0, 0.0, x, u, c->out, du, m->user);
  }
  return rc;
}

/* CPU seconds spent in the model callbacks per integration: calls (counted) x the time of
 * one call (timed in a loop; these models are a few flops, so cache effects do not matter) */
static double model_time(const fesd_problem *P, const fesd_settings *set, int nsim, double *calls) {
  count_model w = {P->model, {0, 0, 0, 0}};
  fesd_problem Q = *P;
  Q.model.field = c_field;
  Q.model.field_jac = P->model.field_jac ? c_field_jac : NULL;
  Q.model.sw = c_sw;
  Q.model.sw_jac = P->model.sw_jac ? c_sw_jac : NULL;
  Q.model.user = &w;
  fesd_integrator *it = bench_create(&Q, set);
  if (!it) return NAN;
  bench_job j = {it, &Q, nsim, Q.T};
  int st = bench_integrate(&j, NULL);
  fesd_free(&it);
  double t = 0;
  *calls = (double)(w.calls[0] + w.calls[1] + w.calls[2] + w.calls[3]);
  for (int k = 0; k < 4 && !st; k++)
    if (w.calls[k]) {
      call_ctx c = {P, k, {0}, {0}};
      t += w.calls[k] * 1e-3 * bench_time(call_loop, &c);
    }
  return st ? NAN : t;
}

/* ---- the limit: dense LU + solve of order n ---- */
typedef struct {
  int n;
  double *A, *W, *b;
  int *piv;
} lu_ctx;

static int lu_run(void *ctx) {
  lu_ctx *c = ctx;
  int info, one = 1;
  memcpy(c->W, c->A, (size_t)c->n * c->n * sizeof(double));
  dgetrf_(&c->n, &c->n, c->W, &c->n, c->piv, &info);
  for (int i = 0; i < c->n; i++) c->b[i] = 1.0;
  if (!info) dgetrs_("N", &c->n, &one, c->W, &c->n, c->piv, c->b, &c->n, &info, 1);
  return info;
}

static double time_lu(int n) {
  static int cached_n = -1;
  static double cached_t;
  if (n == cached_n) return cached_t;
  lu_ctx c = {n, malloc((size_t)n * n * sizeof(double)), malloc((size_t)n * n * sizeof(double)),
              malloc((size_t)n * sizeof(double)), malloc((size_t)n * sizeof(int))};
  unsigned long long s = 12345;
  for (int k = 0; k < n * n; k++) {
    s = s * 6364136223846793005ULL + 1442695040888963407ULL;
    c.A[k] = (double)(s >> 11) / 9007199254740992.0 - 0.5;
  }
  for (int i = 0; i < n; i++) c.A[i * n + i] += n; /* well conditioned */
  double t = c.A && c.W && c.b && c.piv ? bench_time(lu_run, &c) : NAN;
  free(c.A), free(c.W), free(c.b), free(c.piv);
  cached_n = n;
  return cached_t = t;
}

static int timed_integration(void *ctx) {
  double t0 = wall();
  int st = bench_integrate((const bench_job *)ctx, NULL);
  acc.wall += wall() - t0;
  return st;
}

typedef struct {
  const char *prob;
  fesd_method method;
  int s, nsim;
} bench_case;

typedef struct {
  double share, calls; /* share of the CPU time, calls per integration */
} model_cost;

/* One CSV row: P integrated with the case's settings, backend b and at most `sweeps`
 * consistency sweeps per step (8: the default; 1: Newton-driven, nearly every step iterates).
 * The model cost is measured when mc->share is NaN (first backend) and reused for the others
 * (the calls do not depend on the backend). */
static void measure(FILE *csv, const fesd_problem *P, const bench_case *c, fesd_ncp_backend b, int sweeps,
                    model_cost *mc) {
  fesd_settings set;
  fesd_settings_default(&set);
  set.method = c->method;
  set.stages = c->s;
  set.max_sweeps = sweeps;
  set.ncp.backend = b;
  fesd_integrator *it = bench_create(P, &set);
  if (!it) return;
  bench_job j = {it, P, c->nsim, P->T};
  bench_run r;
  memset(&acc, 0, sizeof acc);
  int st = bench_integrate(&j, &r); /* counts per integration */
  const int n = acc.max_rows, steps = r.stats.steps > 0 ? r.stats.steps : 1;
  const double solves = (double)acc.solves / steps, rows = (double)acc.set_rows_calls / steps;
  memset(&acc, 0, sizeof acc); /* shares: sums over the timed integrations */
  double t = st ? NAN : bench_time(timed_integration, &j);
  fesd_free(&it);
  double sh_eval = acc.eval / acc.wall, sh_lin = acc.linsolve / acc.wall, sh_rows = acc.set_rows / acc.wall;
  double sh_solver = (acc.total - acc.eval - acc.linsolve) / acc.wall;
  double sh_out = 1 - (acc.total + acc.set_rows) / acc.wall;
  /* the library's own factorization + solve of the step Jacobian, and one iteration of its
   * Newton loop (both wall time inside the solver, summed over the timed integrations) */
  double us_fact = 1e6 * acc.linsolve / (double)(acc.factorizations ? acc.factorizations : 1);
  double us_iter = acc.iterations ? 1e6 * acc.iter_time / (double)acc.iterations : NAN;
  if (isnan(mc->share) && !st) mc->share = model_time(P, &set, c->nsim, &mc->calls) / t;
  double lu = n > 0 ? time_lu(n) : NAN, per_newton = t / (r.stats.newton_iter ? r.stats.newton_iter : 1);
  const char *mname = c->method ? "standard" : "fesd", *bname = fesd_ncp_backend_name(b);
  fprintf(csv, "%s,%s,%d,%d,%d,%s,%d,%d,%.3f,%.3f,%.3f,%.3f,%.4f,%.2f,%.2f,%.2f,", P->name, mname, c->s, c->nsim,
          sweeps, bname, n, r.stats.steps, (double)r.stats.newton_iter / steps, (double)r.stats.factorizations / steps,
          solves, rows, 1e3 * t, 1e6 * t / steps, 1e6 * per_newton, us_iter);
  fprintf(csv, "%.3f,%.3f,%.3f,%.3f,%.3f,%.3f,%.1f,%.2f,%.2f,%.3f,%.3f,%.3f,%.3f,%d\n", sh_eval, sh_lin, sh_solver,
          sh_rows, sh_out, mc->share, mc->calls / steps, us_fact, 1e6 * lu, per_newton / lu, 1e-6 * us_iter / lu,
          us_iter / us_fact, 1e-6 * us_fact / lu, st);
  printf("%-12s %-8s %d %3d %d %-7s %3d | %6.1f %5.2f | %3.0f%% %3.0f%% %3.0f%% %3.0f%% %3.0f%% | %3.0f%% | %7.1f %6.1f "
         "%6.1f %6.1f | %5.2f %5.2f %5.2f%s\n", P->name, mname, c->s, c->nsim, sweeps, bname, n, 1e6 * t / steps,
         (double)r.stats.newton_iter / steps, 100 * sh_eval, 100 * sh_lin, 100 * sh_solver, 100 * sh_rows, 100 * sh_out,
         100 * mc->share, 1e6 * per_newton, us_iter, us_fact, 1e6 * lu, per_newton / lu, 1e-6 * us_iter / lu,
         us_iter / us_fact, st ? "  FAILED" : "");
  fflush(stdout);
}

/* Time per step of the standard method against FESD on the same problem, settings and
 * solver, measured in alternating rounds (bench_time_pair): the ratio does not depend on
 * the machine's drift between two separate measurements. */
static void standard_vs_fesd(FILE *csv, const char *prob, int s, int nsim) {
  fesd_problem P;
  fesd_problem_get(prob, &P);
  fesd_integrator *it[2] = {NULL, NULL};
  bench_job j[2];
  int steps[2] = {0, 0};
  for (int k = 0; k < 2; k++) {
    fesd_settings set;
    fesd_settings_default(&set);
    set.method = k ? FESD_METHOD_STANDARD : FESD_METHOD_FESD;
    set.stages = s;
    it[k] = bench_create(&P, &set);
    j[k] = (bench_job){it[k], &P, nsim, P.T};
    bench_run r;
    if (it[k] && !bench_integrate(&j[k], &r)) steps[k] = r.stats.steps;
  }
  double tf = NAN, ts = NAN, ratio = NAN;
  if (steps[0] > 0 && steps[1] > 0) {
    ratio = bench_time_pair(bench_integrate_fn, &j[0], bench_integrate_fn, &j[1], &tf, &ts);
    ratio *= (double)steps[0] / steps[1];
  }
  const double uf = 1e6 * tf / steps[0], us = 1e6 * ts / steps[1];
  fprintf(csv, "%s,%d,%d,%d,%d,%.3f,%.3f,%.4f\n", prob, s, nsim, steps[0], steps[1], uf, us, ratio);
  printf("%-12s s=%d N=%3d: us/step FESD %6.2f standard %6.2f, standard/FESD %.3f (paired rounds)\n", prob, s, nsim,
         uf, us, ratio);
  fesd_free(&it[0]);
  fesd_free(&it[1]);
}

int main(int argc, char **argv) {
  if (bench_init(argc, argv, "cost anatomy per backend, against one LU + solve")) return 1;
  FILE *csv = bench_csv("anatomy.csv",
                        "problem,method,s,nsim,max_sweeps,backend,n,steps,newton_per_step,fact_per_step,solves_per_step,"
                        "set_rows_per_step,cpu_ms,us_per_step,us_per_newton,us_per_iteration,share_eval,share_linsolve,"
                        "share_solver_other,share_set_rows,share_outside,share_model,model_calls_per_step,"
                        "us_lib_factor_solve,us_lapack_lu,ratio_newton_to_lu,ratio_iteration_to_lu,"
                        "ratio_iteration_to_lib,ratio_factor_to_lu,status");
  if (!csv) return 1;
  static const bench_case cases[] = {
      {"oscillator", FESD_METHOD_FESD, 5, 10},     {"oscillator", FESD_METHOD_FESD, 3, 40},
      {"oscillator", FESD_METHOD_STANDARD, 3, 40}, {"sign-c", FESD_METHOD_FESD, 2, 20},
      {"sign-c", FESD_METHOD_STANDARD, 2, 20},     {"ocp-dynamics", FESD_METHOD_FESD, 2, 40},
      {"ocp-dynamics", FESD_METHOD_STANDARD, 2, 40}};
  static const fesd_ncp_backend backends[] = {FESD_NCP_BACKEND_AUTO, FESD_NCP_BACKEND_DENSE, FESD_NCP_BACKEND_KLU,
                                              FESD_NCP_BACKEND_UMFPACK};
  static const int sweeps[] = {8, 1};
  const int nc = bench_opt.quick ? 2 : 7, nb = bench_opt.quick ? 2 : 4;
  printf("all/newton: integration time per Newton iteration; iteration: one iteration of the Newton loop;\n"
         "lib LU: the backend's factorization + solve of the same Jacobian; LAPACK: dgetrf + dgetrs of the same order\n");
  printf("%-12s %-8s s  N sw backend   n | us/step newt/st | eval lin  slv rows out | model |"
         " all/newt iterat lib LU LAPACK | all/LAPACK iter/LAPACK iter/lib\n", "problem", "method");
  for (int c = 0; c < nc; c++) {
    fesd_problem P;
    fesd_problem_get(cases[c].prob, &P);
    model_cost mc = {NAN, NAN};
    for (int w = 0; w < 2; w++)
      for (int b = 0; b < nb; b++) measure(csv, &P, &cases[c], backends[b], sweeps[w], &mc);
  }
  fclose(csv);
  csv = bench_csv("anatomy_pairs.csv", "problem,s,nsim,steps_fesd,steps_std,us_per_step_fesd,us_per_step_std,"
                                       "ratio_std_to_fesd");
  if (!csv) return 1;
  printf("\nstandard time-stepping against FESD per step (same settings, solver and backend auto):\n");
  for (int c = 0; c < nc; c++)
    if (cases[c].method == FESD_METHOD_FESD) standard_vs_fesd(csv, cases[c].prob, cases[c].s, cases[c].nsim);
  fclose(csv);
  return 0;
}
