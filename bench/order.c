/* Integration order on the oscillator (paper Sec. 4.4, Fig. integrator_order): every RK
 * family and s = 1..4 (Lobatto from 2), FESD and standard time-stepping, N_FE = 2,
 * error at T against the nominal step h = T / N_sim; fitted slopes.
 * Grids and fits as tests/fesd/test_order.c: FESD's error is smooth in h only once the
 * switch falls inside its step, so the slope is a least-squares fit over many grids;
 * the standard method's error is erratic (it depends on where the switch falls in a
 * step), so its slope is that of the upper envelope (worst error at this or a finer grid).
 * Low orders have a large error constant here (|lambda| h ~ 2 pi h): grids 8x finer for p <= 2.
 * Output: order.csv (every run), order_slopes.csv (one row per tableau). */
#include <math.h>

#include "bench_util.h"

#define MAXG 40

static double run(const fesd_problem *P, fesd_settings *set, int nsim, double *ts_err, int *iters) {
  *ts_err = NAN;
  *iters = 0;
  fesd_integrator *it = bench_create(P, set);
  if (!it) return NAN;
  bench_job j = {it, P, nsim, P->T};
  bench_run r;
  int st = bench_integrate(&j, &r);
  fesd_free(&it);
  *ts_err = fabs(bench_event_near(&r, 1.0, -1) - 1.0);
  *iters = r.stats.newton_iter;
  return st ? NAN : r.err;
}

int main(int argc, char **argv) {
  if (bench_init(argc, argv, "oscillator: error vs h for every tableau, FESD and standard")) return 1;
  const int ngrid = bench_opt.quick ? 6 : 30, nstd = bench_opt.quick ? 5 : 25;
  fesd_problem P;
  fesd_problem_get("oscillator", &P);
  FILE *runs = bench_csv("order.csv", "family,s,p,method,nsim,h,err,ts_err,newton_iter");
  FILE *fit = bench_csv("order_slopes.csv",
                        "family,s,p,slope_fesd,points_fesd,slope_ts_fesd,slope_std,points_std,"
                        "err_fesd_finest,err_std_finest");
  if (!runs || !fit) return 1;
  printf("%-10s %s %2s | %-9s %-9s %-9s | %s\n", "family", "s", "p", "FESD", "t_s", "standard",
         "finest FESD / standard error");
  int failures = 0;
  for (int fam = 0; fam < FESD_RK_NUM_FAMILIES; fam++)
    for (int s = 1; s <= 4; s++) {
      const int p = fesd_rk_order((fesd_rk_family)fam, s);
      if (p < 0) continue;
      const int scale = p <= 2 ? 8 : 1;
      fesd_settings set;
      fesd_settings_default(&set);
      set.family = (fesd_rk_family)fam;
      set.stages = s;
      const char *fname = fesd_rk_family_name(set.family);
      double hf[MAXG], ef[MAXG], tf[MAXG], hs[MAXG], es[MAXG], env[MAXG];
      int ng = 0, last = 0;
      for (int g = 0; g < ngrid; g++) { /* N log-spaced over [4, 320] (x scale), deduplicated */
        int nsim = (int)lround(4.0 * scale * pow(80.0, (double)g / (ngrid - 1)));
        if (nsim == last) continue;
        last = nsim;
        int iters;
        set.method = FESD_METHOD_FESD;
        hf[ng] = P.T / nsim;
        ef[ng] = run(&P, &set, nsim, &tf[ng], &iters);
        failures += isnan(ef[ng]);
        fprintf(runs, "%s,%d,%d,fesd,%d,%.6e,%.6e,%.6e,%d\n", fname, s, p, nsim, hf[ng], ef[ng], tf[ng], iters);
        ng++;
      }
      for (int g = 0; g < nstd; g++) { /* standard: [10, 320] (x scale, x4 more for p <= 2) */
        int nsim = (int)lround(10.0 * scale * (p <= 2 ? 4 : 1) * pow(32.0, (double)g / (nstd - 1))), iters;
        double ts;
        set.method = FESD_METHOD_STANDARD;
        hs[g] = P.T / nsim;
        es[g] = run(&P, &set, nsim, &ts, &iters);
        failures += isnan(es[g]);
        fprintf(runs, "%s,%d,%d,standard,%d,%.6e,%.6e,%.6e,%d\n", fname, s, p, nsim, hs[g], es[g], ts, iters);
      }
      for (int g = nstd - 1; g >= 0; g--) env[g] = g == nstd - 1 ? es[g] : fmax(es[g], env[g + 1]);
      int uf, ut, us;
      /* above round-off (1e-11) and inside the asymptotic range (< 0.5) */
      double pf = bench_slope(hf, ef, ng, 1e-11, 0.5, &uf), pt = bench_slope(hf, tf, ng, 1e-11, 0.5, &ut);
      double ps = bench_slope(hs, env, nstd, 1e-11, 0.5, &us);
      fprintf(fit, "%s,%d,%d,%.3f,%d,%.3f,%.3f,%d,%.3e,%.3e\n", fname, s, p, pf, uf, pt, ps, us, ef[ng - 1],
              es[nstd - 1]);
      printf("%-10s %d %2d | %5.2f(%2d) %5.2f(%2d) %5.2f(%2d) | %.1e / %.1e\n", fname, s, p, pf, uf, pt, ut, ps,
             us, ef[ng - 1], es[nstd - 1]);
    }
  fclose(runs);
  fclose(fit);
  if (failures) printf("%d runs failed (NaN in order.csv)\n", failures);
  return 0;
}
