/* Accuracy against CPU time of the ocp_step_eq OCP (paper Fig. pareto_lots): every discretisation
 * solves the same OCP (N_ctrl = 6, same initial guess, same optimizer: fesd_ocp defaults); the
 * optimal piecewise constant controls are re-simulated with high accuracy (FESD Radau IIA s = 4,
 * 40 steps per interval, converged to ~1e-13) and E(T) = ||q_sim(4) - q_final||_2 is plotted
 * against the CPU time of the solve (initial guess + SQP; median of 3 repetitions, --quick: 1).
 * Grid: FESD and standard time-stepping; Radau IIA, Lobatto IIIC, Gauss-Legendre, explicit RK;
 * s = 1..4 (Lobatto IIIC from 2); N_FE = 2..7 (standard also 1); --quick: Radau IIA and Lobatto
 * IIIC, s = 1..3 (from 2 for Lobatto), N_FE = 2, 4. Every solve with settings.presolve = 1 (the
 * default: an implicit-Euler standard solve first) and 0 (from the guess).
 * Fronts of the targets: FESD with the default; the standard method over both settings (the best
 * it reaches with either, so the ratio does not credit FESD with a choice the standard method
 * could make too). The *_nopresolve rows: both methods without the presolve (the definition
 * before the presolve existed), from the same run.
 * Outputs: ocp_pareto.csv (one row per solve), ocp_pareto_summary.csv (the targets below); the
 * plot: gnuplot -e "dir='OUTDIR'" tools/plot.gp.
 * Targets (reported, not asserted): FESD at least 1e3 times more accurate than the standard
 * method at equal CPU time over the standard method's CPU range (Pareto fronts over all
 * families, log-log interpolated); every FESD Radau IIA solve with s <= 3, N_FE <= 4 under 100 ms.
 * The ratio exists only where both fronts do: from the cheapest converged FESD solve on. The
 * part of the standard's range below it (no FESD solve is that cheap) is reported as
 * ratio_uncovered_fraction (of the log CPU range) and fesd_ms_min, and the time of the minimum
 * as ratio_min_at_ms, so that a minimum over the overlap is not read as one over the whole
 * range. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "bench_util.h"

#define NCTRL 6
#define MAXP 512

typedef struct {
  int method, family, s, nfe, presolve, status, iterations;
  double ms, E, f;
} run;

static run runs[MAXP];
static int nruns;

static int solve(fesd_ocp *o, const double *ug, double *u, fesd_ocp_info *info) {
  fesd_ocp_set_guess(o, NULL, ug);
  int st = fesd_ocp_solve(o, info);
  fesd_ocp_get_solution(o, NULL, u);
  return st;
}

static void one(const fesd_problem *P, FILE *csv, int method, fesd_rk_family fam, int s, int nfe, int presolve) {
  fesd_ocp_problem op;
  fesd_ocp_step_eq(&op, &P->model);
  fesd_ocp_settings set;
  fesd_ocp_settings_default(&set);
  set.integrator.method = method ? FESD_METHOD_STANDARD : FESD_METHOD_FESD;
  set.integrator.family = fam;
  set.integrator.stages = s;
  set.integrator.n_fe = nfe;
  set.presolve = presolve;
  fesd_ocp *o;
  if (fesd_ocp_create(&o, &op, &set)) return;
  double ug[2 * NCTRL], u[2 * NCTRL], t[3], xT[4];
  fesd_ocp_step_eq_guess(ug, NCTRL);
  fesd_ocp_info info;
  int st = 0, reps = bench_opt.quick ? 1 : 3;
  for (int r = 0; r < reps; r++) {
    double t0 = bench_cpu();
    st = solve(o, ug, u, &info);
    t[r] = bench_cpu() - t0;
  }
  const double ms = 1e3 * bench_median(t, reps);
  double E = NAN;
  if (!fesd_ocp_step_eq_resimulate(&P->model, P->x0, u, NCTRL, 4.0, 40, xT)) E = fesd_ocp_step_eq_error(xT);
  const char *mname = method ? "standard" : "fesd", *fname = fesd_rk_family_name(fam);
  fprintf(csv, "%s,%s,%d,%d,%s,%d,%.4f,%.4f,%.4f,%.4e,%.10f,%.2e,%.2e,%d,%d,%d,%d\n", mname, fname, s, nfe,
          fesd_status_name(st), info.iterations, ms, 1e3 * info.time_integration, 1e3 * info.time_qp, E,
          info.objective, info.stationarity_rel, info.feasibility, info.integrations, presolve,
          info.presolve_used, info.presolve_iterations);
  printf("  %-8s %-9s s=%d N_FE=%d pre %d/%d  %-22s %3d it  %4d int  %8.2f ms  E(T) %.2e  f %.8f\n", mname, fname,
         s, nfe, presolve, info.presolve_used, fesd_status_name(st), info.iterations, info.integrations, ms, E,
         info.objective);
  fflush(stdout);
  if (nruns < MAXP)
    runs[nruns++] = (run){method, (int)fam, s, nfe, presolve, st, info.iterations, ms, E, info.objective};
  fesd_ocp_free(&o);
}

/* Pareto front of the converged solves of one method with the presolve settings in mask
 * (bit p: settings.presolve = p) */
static int front(int method, int mask, bench_point *F) {
  bench_point p[MAXP];
  int n = 0;
  for (int i = 0; i < nruns; i++)
    if (runs[i].method == method && (mask >> runs[i].presolve & 1) && runs[i].status == FESD_OK)
      p[n++] = (bench_point){runs[i].ms, runs[i].E, i};
  return bench_front(p, n, F);
}

/* The targets for the FESD solves in fmask against the standard ones in smask (front masks);
 * rows named with the suffix sfx */
static void targets(FILE *sum, int fmask, int smask, const char *sfx) {
  bench_point F[MAXP], S[MAXP];
  const int kf = front(0, fmask, F), ks = front(1, smask, S);
  double rmin = INFINITY, lsum = 0, t_rmin = NAN;
  int m = 0, n_grid = 0;
  for (int i = 0; i <= 40 && kf && ks; i++) { /* log-spaced over the standard method's CPU range */
    const double lo = S[0].t, hi = S[ks - 1].t, tt = lo * pow(hi / lo, i / 40.0);
    const double r = bench_front_err(S, ks, tt) / bench_front_err(F, kf, tt);
    n_grid++;
    if (!isfinite(r)) continue; /* before the first FESD point */
    if (r < rmin) rmin = r, t_rmin = tt;
    lsum += log(r), m++;
  }
  const double uncovered = kf && ks ? fmax(0.0, fmin(1.0, log(F[0].t / S[0].t) / log(S[ks - 1].t / S[0].t))) : NAN;
  double worst_ms = 0;
  int n_small = 0, n_small_ok = 0;
  for (int i = 0; i < nruns; i++)
    if (runs[i].method == 0 && (fmask >> runs[i].presolve & 1) && runs[i].family == FESD_RK_RADAU_IIA &&
        runs[i].s <= 3 && runs[i].nfe <= 4) {
      n_small++, n_small_ok += runs[i].status == FESD_OK;
      worst_ms = fmax(worst_ms, runs[i].ms);
    }
  int nok[2] = {0, 0}, nall[2] = {0, 0};
  for (int i = 0; i < nruns; i++)
    if ((runs[i].method ? smask : fmask) >> runs[i].presolve & 1)
      nall[runs[i].method]++, nok[runs[i].method] += runs[i].status == FESD_OK;
  fprintf(sum, "fesd_solves%s,%d\nfesd_converged%s,%d\nstandard_solves%s,%d\nstandard_converged%s,%d\n", sfx, nall[0],
          sfx, nok[0], sfx, nall[1], sfx, nok[1]);
  fprintf(sum, "ratio_min_equal_cpu%s,%.3e\nratio_geomean_equal_cpu%s,%.3e\n", sfx, m ? rmin : NAN, sfx,
          m ? exp(lsum / m) : NAN);
  fprintf(sum, "ratio_min_at_ms%s,%.3f\nratio_grid_points%s,%d\nratio_grid_points_defined%s,%d\n", sfx, t_rmin, sfx,
          n_grid, sfx, m);
  fprintf(sum, "standard_ms_min%s,%.3f\nfesd_ms_min%s,%.3f\nratio_uncovered_fraction%s,%.3f\n", sfx,
          ks ? S[0].t : NAN, sfx, kf ? F[0].t : NAN, sfx, uncovered);
  fprintf(sum, "fesd_best_E%s,%.3e\nstandard_best_E%s,%.3e\n", sfx, kf ? F[kf - 1].e : NAN, sfx,
          ks ? S[ks - 1].e : NAN);
  fprintf(sum, "fesd_ms_to_standard_best%s,%.3f\nstandard_ms_best%s,%.3f\n", sfx,
          kf && ks ? bench_front_time(F, kf, S[ks - 1].e) : NAN, sfx, ks ? S[ks - 1].t : NAN);
  fprintf(sum, "radau_s3_nfe4_solves%s,%d\nradau_s3_nfe4_converged%s,%d\nradau_s3_nfe4_max_ms%s,%.3f\n", sfx,
          n_small, sfx, n_small_ok, sfx, worst_ms);
  printf("%s: converged: FESD %d/%d, standard %d/%d\n", *sfx ? sfx + 1 : "fronts for the targets", nok[0], nall[0],
         nok[1], nall[1]);
  printf("  error ratio standard / FESD at equal CPU time over the standard's range: min %.1e (at %.1f ms), "
         "geometric mean %.1e (target: >= 1e3), defined at %d of %d grid times: below %.1f ms (the cheapest "
         "converged FESD solve; standard from %.1f ms) no FESD solve exists, %.0f %% of the log range\n",
         m ? rmin : NAN, t_rmin, m ? exp(lsum / m) : NAN, m, n_grid, kf ? F[0].t : NAN, ks ? S[0].t : NAN,
         100 * uncovered);
  printf("  FESD Radau IIA s <= 3, N_FE <= 4: %d/%d converged, slowest %.1f ms (target: < 100 ms)\n", n_small_ok,
         n_small, worst_ms);
}

int main(int argc, char **argv) {
  if (bench_init(argc, argv, "ocp_step_eq: terminal error of the re-simulated optimal controls vs CPU time"))
    return 1;
  FILE *csv = bench_csv("ocp_pareto.csv", "method,family,s,nfe,status,iterations,cpu_ms,cpu_int_ms,cpu_qp_ms,E,"
                                          "objective,stationarity,feasibility,integrations,presolve,presolve_used,"
                                          "presolve_iterations");
  FILE *sum = bench_csv("ocp_pareto_summary.csv", "quantity,value");
  if (!csv || !sum) return 1;
  fesd_problem P;
  fesd_problem_get("ocp-dynamics", &P);
  static const fesd_rk_family fams[] = {FESD_RK_RADAU_IIA, FESD_RK_LOBATTO_IIIC, FESD_RK_GAUSS_LEGENDRE,
                                        FESD_RK_EXPLICIT};
  const int nfam = bench_opt.quick ? 2 : 4, smax = bench_opt.quick ? 3 : 4;
  for (int presolve = 1; presolve >= 0; presolve--)
    for (int method = 0; method < 2; method++)
      for (int a = 0; a < nfam; a++)
        for (int s = fams[a] == FESD_RK_LOBATTO_IIIC ? 2 : 1; s <= smax; s++)
          for (int nfe = method ? 1 : 2; nfe <= 7; nfe++) {
            if (bench_opt.quick && nfe != 2 && nfe != 4) continue;
            one(&P, csv, method, fams[a], s, nfe, presolve);
          }
  targets(sum, 2, 3, "");
  targets(sum, 1, 1, "_nopresolve");
  fclose(csv);
  fclose(sum);
  return 0;
}
