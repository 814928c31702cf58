/* Speed against error (Pareto): CPU time per integration vs error, FESD against standard
 * time-stepping (same tableau, same N_FE = 2, same solver), Radau IIA s = 1..5, N_sim
 * doubling. Problems:
 *   oscillator    T = pi/2, crossing at t = 1; error = |x(T) - exact|_inf
 *   sign-c        T = 2.1, leaves a sliding mode at t = 1; error = |x(T) - exact|_inf;
 *                 third curve: FESD with the paper's formulation at the exit (exit_rows = 0)
 *   ocp-dynamics  T = 4, two sliding entries (t1 ~ 0.9775, 2 pi / 3); both methods give x(T)
 *                 (the origin, reached by attractive sliding) to round-off, so the plotted
 *                 error is the switch-time error max_k |t_k - t_k*| (events at element
 *                 boundaries; the standard method's boundaries are on its fixed grid).
 * A (variant, s) sweep stops once the error is below 1e-13 (finer grids only cost more).
 * Headline numbers per problem (pareto_summary.csv): the Pareto front of a variant is its
 * best error within a CPU budget t, interpolated linearly in log-log between front points
 * (and constant after its last point: more budget cannot hurt). Ratio of standard to
 * FESD error at equal CPU time over the standard method's range; the CPU time FESD needs
 * for the best error the standard method reaches in the sweep.
 * Performance targets (targets.csv): the cheapest FESD run that reaches the target error
 * (state error at T) against the target CPU time. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "bench_util.h"

#define PI 3.14159265358979323846
#define MAXP 128

typedef struct {
  const char *variant;
  fesd_method method;
  int exit_rows;
} variant;

typedef struct {
  double t, e, es; /* CPU seconds, plotted error, state error */
  int s, nsim;
} point;

static const variant V_FESD = {"fesd", FESD_METHOD_FESD, 1}, V_STD = {"standard", FESD_METHOD_STANDARD, 1},
                     V_PAPER = {"fesd-exit0", FESD_METHOD_FESD, 0};

/* Pareto front of the points (bench_front on their (time, error) pairs). */
static int front(const point *p, int n, bench_point *f) {
  bench_point q[MAXP];
  for (int i = 0; i < n; i++) q[i] = (bench_point){p[i].t, p[i].e, i};
  return bench_front(q, n, f);
}
#define front_err bench_front_err
#define front_time bench_front_time

/* max_k |t_k - t_k*| over the expected switches (nearest event of any kind) */
static double switch_err(const fesd_problem *P, const bench_run *r) {
  const int ocp = !strcmp(P->name, "ocp-dynamics");
  const double ts[2] = {P->t_switch, 2 * PI / 3};
  double e = 0;
  for (int k = 0; k < 1 + ocp; k++) e = fmax(e, fabs(bench_event_near(r, ts[k], -1) - ts[k]));
  return isnan(e) ? INFINITY : e;
}

static FILE *csv;

/* Sweep one variant over s and N_sim; returns the number of points. */
static int sweep(const fesd_problem *P, const variant *v, const int *stages, int ns, const int *grid, int ng,
                 point *pts) {
  int n = 0;
  for (int a = 0; a < ns; a++) {
    fesd_settings set;
    fesd_settings_default(&set);
    set.method = v->method;
    set.exit_rows = v->exit_rows;
    set.stages = stages[a];
    fesd_integrator *it = bench_create(P, &set);
    if (!it) continue;
    for (int g = 0; g < ng && n < MAXP; g++) {
      bench_job j = {it, P, grid[g], P->T};
      bench_run r;
      int st = bench_integrate(&j, &r);
      double es = st ? NAN : r.err, esw = st ? NAN : switch_err(P, &r);
      double e = strcmp(P->name, "ocp-dynamics") ? es : esw, t = st ? NAN : bench_time(bench_integrate_fn, &j);
      pts[n++] = (point){t, e, es, stages[a], grid[g]};
      const fesd_stats *S = &r.stats;
      fprintf(csv, "%s,%s,radau,%d,%d,%.6e,%.6e,%.6e,%.6e,%d,%d,%d,%d,%d,%d,%.3e,%d\n", P->name, v->variant,
              stages[a], grid[g], 1e3 * t, e, es, esw, S->steps, S->newton_iter,
              S->factorizations, S->switch_steps, S->fallback_steps, S->splits, r.max_residual, st);
      printf("  %-13s %-10s s=%d N=%4d  %8.3f ms  err %.2e  iters %4d%s\n", P->name, v->variant, stages[a],
             grid[g], 1e3 * t, e, S->newton_iter, st ? "  FAILED" : "");
      fflush(stdout);
      if (st || e < 1e-13) break;
    }
    fesd_free(&it);
  }
  return n;
}

static FILE *summary, *targets;

static void compare(const char *prob, const char *vname, const point *pf, int nf, const point *ps, int ns) {
  bench_point F[MAXP], S[MAXP];
  int kf = front(pf, nf, F), ks = front(ps, ns, S);
  if (!kf || !ks) return;
  double lo = fmax(F[0].t, S[0].t), hi = S[ks - 1].t, lsum = 0, rmin = INFINITY, rmax = 0;
  int m = 0;
  for (int i = 0; i <= 40 && lo <= hi; i++) { /* log-spaced samples of the common range */
    double t = lo * pow(hi / lo, i / 40.0), r = front_err(S, ks, t) / front_err(F, kf, t);
    if (!isfinite(r)) continue;
    lsum += log(r), rmin = fmin(rmin, r), rmax = fmax(rmax, r), m++;
  }
  double gm = m ? exp(lsum / m) : NAN, best = S[ks - 1].e, tf = front_time(F, kf, best), tsb = S[ks - 1].t;
  fprintf(summary, "%s,%s,%.3e,%.3e,%.3e,%.3e,%.3e,%d,%d,%.4f,%.4f,%.3e\n", prob, vname, gm, m ? rmin : NAN,
          m ? rmax : NAN, best, F[kf - 1].e, ps[S[ks - 1].id].s, ps[S[ks - 1].id].nsim, 1e3 * tsb, 1e3 * tf, tsb / tf);
  printf("%s, %s vs standard: error ratio at equal CPU time %.1e (range %.1e .. %.1e); standard's best "
         "error %.1e at %.3f ms, %s reaches it in %.3f ms (%.1fx faster)\n",
         prob, vname, gm, rmin, rmax, best, 1e3 * tsb, vname, 1e3 * tf, tsb / tf);
}

static void target(const char *prob, const point *p, int n, double err, double ms) {
  int best = -1;
  for (int i = 0; i < n; i++)
    if (p[i].es <= err && isfinite(p[i].t) && (best < 0 || p[i].t < p[best].t)) best = i;
  if (best < 0) {
    fprintf(targets, "%s,%.0e,%.3f,nan,nan,nan,nan,nan\n", prob, err, ms);
    return;
  }
  fprintf(targets, "%s,%.0e,%.3f,%d,%d,%.3e,%.4f,%.3f\n", prob, err, ms, p[best].s, p[best].nsim, p[best].es,
          1e3 * p[best].t, 1e3 * p[best].t / ms);
}

int main(int argc, char **argv) {
  if (bench_init(argc, argv, "CPU time vs error, FESD vs standard (oscillator, sign-c, ocp-dynamics)")) return 1;
  csv = bench_csv("pareto.csv", "problem,variant,family,s,nsim,cpu_ms,err,err_state,err_switch,steps,"
                                "newton_iter,factorizations,switch_steps,fallback_steps,splits,max_residual,status");
  summary = bench_csv("pareto_summary.csv", "problem,variant,ratio_equal_cpu,ratio_min,ratio_max,std_best_err,"
                                            "fesd_best_err,std_best_s,std_best_nsim,std_best_ms,fesd_ms_to_std_best,"
                                            "speedup");
  targets = bench_csv("targets.csv", "problem,target_err,target_ms,s,nsim,err,cpu_ms,ratio_to_target");
  if (!csv || !summary || !targets) return 1;
  static const int full_s[] = {1, 2, 3, 4, 5}, quick_s[] = {2, 3};
  static const int full_n[] = {5, 10, 20, 40, 80, 160, 320, 640}, quick_n[] = {5, 20};
  const int *st = bench_opt.quick ? quick_s : full_s, *gr = bench_opt.quick ? quick_n : full_n;
  const int ns = bench_opt.quick ? 2 : 5, ng = bench_opt.quick ? 2 : 8;
  static const struct {
    const char *name;
    double target_err, target_ms;
  } probs[] = {{"oscillator", 1e-10, 0.5}, {"sign-c", 1e-10, 2.0}, {"ocp-dynamics", 1e-8, 5.0}};
  static point pf[MAXP], pp[MAXP], ps[MAXP];
  for (int k = 0; k < 3; k++) {
    fesd_problem P;
    fesd_problem_get(probs[k].name, &P);
    int nf = sweep(&P, &V_FESD, st, ns, gr, ng - 1, pf); /* FESD: N_sim <= 320 */
    int np = strcmp(P.name, "sign-c") ? 0 : sweep(&P, &V_PAPER, st, ns, gr, ng - 1, pp);
    int nss = sweep(&P, &V_STD, st, ns, gr, ng, ps);
    compare(P.name, "fesd", pf, nf, ps, nss);
    if (np) compare(P.name, "fesd-exit0", pp, np, ps, nss);
    target(P.name, pf, nf, probs[k].target_err, probs[k].target_ms);
  }
  fclose(csv);
  fclose(summary);
  fclose(targets);
  return 0;
}
