/* Growth with problem size: a chain of n masses with Coulomb friction on a belt
 * (n independent switching subsystems, n_x = 2n, sparse model API), n = 8 .. 1024.
 * Belt speed 5: every mass keeps slipping over the horizon, so every step is an ordinary
 * step and the time measures how the sparse step system scales. Two series: "default"
 * (the guess sweeps converge, few Newton iterations) and "newton" (one sweep, so every step
 * factorizes the sparse step Jacobian). CPU time per step by bench_time (median of
 * repetitions). Writes OUTDIR/growth.csv and prints the fitted exponent of time per step
 * against n.
 * Switching series (growth_switching.csv): the stick-slip chain (belt speed 0.2, q_i(0) =
 * sin(1.3 i + 0.4): masses stick and slip at different times, up to n/2 switches in one step),
 * FESD Radau IIA s = 2, h = 0.2, T = 20, one timed run per n: time per simulated second and
 * per (step + event), events, Newton iterations per event (of the steps that hold events) and
 * of the worst step; fitted exponent of the time per (step + event) against n.
 * Chain Pareto (chain_pareto.csv): n = 64, T = 4, FESD against the standard method (same
 * Radau IIA s = 2, 3, N_FE = 2, same solver), h = 0.2 / 2^k; error at T against Lobatto IIIC
 * s = 4 at h = 0.2 / 32; CPU ratio at equal error.
 *   bench_growth [--quick] [--pareto] [OUTDIR]   (--quick: n = 8 .. 128 (switching: .. 64), short
 *                                                  timings; --pareto: the chain Pareto alone) */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "bench_util.h"
#include "problems/friction_chain.h"

typedef struct {
  fesd_integrator *it;
  const double *x0;
  int nsteps;
} chain_job;

static int run_chain(void *ctx) {
  chain_job *j = ctx;
  int st = fesd_set_state(j->it, 0, j->x0, NULL);
  for (int k = 0; k < j->nsteps && !st; k++) st = fesd_step(j->it, NULL, 0.2, NULL);
  return st;
}

/* One run of the stick-slip chain: nsteps steps of h; CPU seconds, events, iterations. */
typedef struct {
  double cpu;
  int st, steps, events, iters, iters_sw, worst;
  double x[2048];
} ss_run;

static int ss_chain(int n, const fesd_settings *set, double h, int nsteps, ss_run *r) {
  fesd_friction_chain fc;
  if (fesd_friction_chain_stick_slip(&fc, n)) return FESD_ERR_NOMEM;
  fesd_integrator *it;
  int st = fesd_create(&it, &fc.model, set);
  memset(r, 0, sizeof *r);
  if (st) {
    fesd_friction_chain_free(&fc);
    return r->st = st;
  }
  const double c0 = bench_cpu();
  st = fesd_set_state(it, 0, fc.x0, NULL);
  for (int k = 0; k < nsteps && !st; k++) {
    fesd_step_info info;
    st = fesd_step(it, NULL, h, &info);
    if (st) break;
    const fesd_event *ev;
    int ne;
    fesd_last_events(it, &ev, &ne);
    r->steps++, r->events += ne, r->iters += info.newton_iter;
    if (ne) r->iters_sw += info.newton_iter;
    if (info.newton_iter > r->worst) r->worst = info.newton_iter;
  }
  r->cpu = bench_cpu() - c0;
  fesd_get_state(it, NULL, r->x);
  fesd_free(&it);
  fesd_friction_chain_free(&fc);
  return r->st = st;
}

static int switching_series(void) {
  FILE *out = bench_csv("growth_switching.csv", "n,steps,events,ms_per_sim_second,ms_per_step_or_event,"
                                                "newton_per_event,worst_step_newton,status");
  if (!out) return 1;
  static ss_run r;
  fesd_settings set;
  fesd_settings_default(&set);
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  int m = 0, rc = 0;
  printf("\nswitching series: stick-slip chain, Radau IIA s = 2, h = 0.2, T = 20\n");
  printf("%6s %7s %9s %14s %16s %12s %11s\n", "n", "events", "max/step", "ms/sim second", "ms/(step+event)",
         "iter/event", "worst step");
  for (int n = 8; n <= (bench_opt.quick ? 64 : 1024); n *= 2) {
    int st = ss_chain(n, &set, 0.2, 100, &r);
    const double per = 1e3 * r.cpu / (r.steps + r.events), pev = r.events ? (double)r.iters_sw / r.events : 0;
    printf("%6d %7d %9s %14.2f %16.3f %12.2f %11d%s\n", n, r.events, "", 1e3 * r.cpu / (0.2 * r.steps), per, pev,
           r.worst, st ? "  FAILED" : "");
    fprintf(out, "%d,%d,%d,%.6f,%.6f,%.3f,%d,%d\n", n, r.steps, r.events, 1e3 * r.cpu / (0.2 * r.steps), per, pev,
            r.worst, st);
    fflush(stdout);
    rc |= st != 0;
    double lx = log((double)n), ly = log(per);
    sx += lx, sy += ly, sxx += lx * lx, sxy += lx * ly, m++;
  }
  printf("switching: fitted exponent of time per (step + event) vs n: %.2f (target <= 1.2)\n",
         (m * sxy - sx * sy) / (m * sxx - sx * sx));
  fclose(out);
  return rc;
}

static int chain_pareto(void) {
  FILE *out = bench_csv("chain_pareto.csv", "method,s,h,cpu_ms,error,events,status");
  if (!out) return 1;
  static ss_run ref, r;
  const int n = 64, K = bench_opt.quick ? 3 : 5;
  const double T = 4;
  fesd_settings set;
  fesd_settings_default(&set);
  set.family = FESD_RK_LOBATTO_IIIC;
  set.stages = 4;
  if (ss_chain(n, &set, 0.2 / 32, (int)lround(T / (0.2 / 32)), &ref)) {
    fprintf(stderr, "bench_growth: chain reference failed\n");
    return 1;
  }
  printf("\nchain n = 64, T = 4: FESD against the standard method (reference Lobatto IIIC s = 4, h = 0.00625, %d "
         "events)\n", ref.events);
  bench_point pf[16], ps[16];
  int nf = 0, nsd = 0;
  for (int meth = 0; meth < 2; meth++)
    for (int s = 2; s <= 3; s++)
      for (int k = 0; k < K; k++) {
        fesd_settings_default(&set);
        set.method = meth ? FESD_METHOD_STANDARD : FESD_METHOD_FESD;
        set.stages = s;
        const double h = 0.2 / (1 << k);
        int st = ss_chain(n, &set, h, (int)lround(T / h), &r);
        double err = st ? NAN : 0;
        for (int i = 0; i < 2 * n && !st; i++) err = fmax(err, fabs(r.x[i] - ref.x[i]));
        const char *name = meth ? "standard" : "fesd";
        printf("  %-8s s=%d h=%-8g %9.2f ms  err %.2e  events %d%s\n", name, s, h, 1e3 * r.cpu, err, r.events,
               st ? "  FAILED" : "");
        fprintf(out, "%s,%d,%g,%.6f,%.6e,%d,%d\n", name, s, h, 1e3 * r.cpu, err, r.events, st);
        bench_point p = {st ? NAN : r.cpu, err, 0};
        if (meth) ps[nsd] = p, ps[nsd].id = nsd, nsd++;
        else pf[nf] = p, pf[nf].id = nf, nf++;
        fflush(stdout);
      }
  bench_point F[16], S[16];
  int kf = bench_front(pf, nf, F), ks = bench_front(ps, nsd, S);
  double lsum = 0, rmin = INFINITY;
  int m = 0;
  if (kf && ks) {
    const double lo = fmax(F[0].t, S[0].t), hi = S[ks - 1].t;
    for (int i = 0; i <= 20 && lo <= hi; i++) {
      const double t = lo * pow(hi / lo, i / 20.0), q = bench_front_err(S, ks, t) / bench_front_err(F, kf, t);
      if (isfinite(q)) lsum += log(q), rmin = fmin(rmin, q), m++;
    }
  }
  printf("chain n = 64: error of standard / FESD at equal CPU time: geometric mean %.3g, min %.3g (%d samples; "
         "target >= 1e3)\n", m ? exp(lsum / m) : NAN, m ? rmin : NAN, m);
  fclose(out);
  return 0;
}

int main(int argc, char **argv) {
  int pareto_only = 0, argn = 1;
  for (int i = 1; i < argc; i++) /* --pareto is this program's own option */
    if (!strcmp(argv[i], "--pareto")) pareto_only = 1;
    else argv[argn++] = argv[i];
  if (bench_init(argn, argv, "bench_growth [--quick] [--pareto] [OUTDIR]")) return 2;
  if (pareto_only) return chain_pareto();
  FILE *out = bench_csv("growth.csv", "series,n,nx,unknowns_per_step,ms_per_step,"
                                      "newton_iter_per_step,factorizations_per_step");
  if (!out) return 1;
  printf("%-8s %6s %6s %9s %12s %10s\n", "series", "n", "n_x", "unknowns", "ms/step", "iter/step");
  const int nsteps = 30, nmax = bench_opt.quick ? 128 : 1024;
  int rc = 0;
  for (int series = 0; series < 2; series++) {
    const char *name = series ? "newton" : "default";
    double sx = 0, sy = 0, sxx = 0, sxy = 0;
    int m = 0;
    for (int n = 8; n <= nmax; n *= 2) {
      fesd_friction_chain fc;
      if (fesd_friction_chain_init(&fc, n, 5.0)) return 1;
      fesd_settings set;
      fesd_settings_default(&set);
      if (series) set.max_sweeps = 1;
      fesd_integrator *it;
      int st = fesd_create(&it, &fc.model, &set);
      if (st) {
        fprintf(stderr, "bench_growth: %s\n", fesd_status_string(st));
        return 1;
      }
      chain_job job = {it, fc.x0, nsteps};
      double ms = 1e3 * bench_time(run_chain, &job) / nsteps;
      fesd_stats S;
      fesd_get_stats(it, &S);
      /* unknowns of one step system: per stage v, theta, lambda, mu; x_{n+1}, h per element */
      int unknowns = set.n_fe * (set.stages * (2 * n + 2 * (2 * n) + n) + 2 * n + 1);
      double iters = (double)S.newton_iter / S.steps;
      printf("%-8s %6d %6d %9d %12.4f %10.2f%s\n", name, n, 2 * n, unknowns, ms, iters,
             isnan(ms) ? "  (failed)" : "");
      fprintf(out, "%s,%d,%d,%d,%.6f,%.3f,%.3f\n", name, n, 2 * n, unknowns, ms, iters,
              (double)S.factorizations / S.steps);
      rc |= isnan(ms);
      double lx = log((double)n), ly = log(ms);
      sx += lx, sy += ly, sxx += lx * lx, sxy += lx * ly, m++;
      fesd_free(&it);
      fesd_friction_chain_free(&fc);
    }
    printf("%s: fitted exponent of time per step vs n: %.2f (target <= 1.2)\n", name,
           (m * sxy - sx * sy) / (m * sxx - sx * sx));
  }
  fclose(out);
  rc |= switching_series();
  rc |= chain_pareto();
  return rc;
}
