/* The optimal control problem ocp_step_eq of the FESD paper (Sec. 6.3) with fesd_ocp:
 *   min int_0^4 u'u + v'v dt + 1e3 ||q(4) - (-pi/6, -pi/4)||_1
 *   q' = -sign(c(q)) + v, v' = u, x(0) = (2pi/3, pi/3, 0, 0), |v| <= 2, |u| <= 10,
 *   c = (q1 + 0.15 q2^2, -0.05 q1^3 + q2) (two subsystems), N_ctrl = 6 intervals.
 * Solves it (default: FESD, Radau IIA s = 2, N_FE = 6), prints the solver statistics, the events
 * and element lengths of every interval, re-simulates the optimal controls with high accuracy
 * (terminal error E(T)) and writes CSVs for examples/ocp_step_eq.gp.
 *
 *   ocp_step_eq [--standard] [--family radau|gauss|lobatto3c|erk] [--stages S] [--nfe N]
 *               [--outdir DIR] [--hessian auto|gn|bfgs|gn-sr1] [--verbose]
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "fesd.h"
#include "problems/problems.h"

#define NCTRL 6

static FILE *open_csv(const char *dir, const char *name, const char *header) {
  char path[1024];
  snprintf(path, sizeof(path), "%s/%s", dir, name);
  FILE *f = fopen(path, "w");
  if (!f) perror(path);
  else fprintf(f, "%s\n", header);
  return f;
}

static const char *kind_name(fesd_event_kind k) {
  return k == FESD_EVENT_CROSSING ? "crossing" : k == FESD_EVENT_SLIDING_ENTRY ? "sliding entry"
                                           : k == FESD_EVENT_SLIDING_EXIT  ? "sliding exit"
                                                                           : "root";
}

/* Re-simulate interval k from x_k with u_k (a fresh integrator with the OCP's settings) and write
 * its elements, events and a dense trajectory. Returns the number of events. */
static int write_interval(const fesd_problem *P, const fesd_settings *is, int k, const double *xk, const double *uk,
                          FILE *traj, FILE *el, FILE *evf) {
  const double T = 4.0 / NCTRL, t0 = k * T;
  fesd_integrator *it;
  if (fesd_create(&it, &P->model, is)) return -1;
  double x[4];
  memcpy(x, xk, sizeof(x));
  int st = fesd_set_state(it, t0, x, uk);
  if (!st) st = fesd_step(it, uk, T, NULL);
  fesd_step_data sd;
  const fesd_event *ev;
  int nev = 0;
  if (!st) st = fesd_last_step_data(it, &sd);
  if (!st) st = fesd_last_events(it, &ev, &nev);
  if (st) {
    fesd_free(&it);
    return -1;
  }
  printf("  interval %d [%.4f, %.4f]: h =", k, t0, t0 + T);
  for (int n = 0; n < sd.n_elements; n++) {
    printf(" %.4f", sd.h[n]);
    if (el) fprintf(el, "%d,%d,%.12g,%.12g\n", k, n, sd.t[n], sd.h[n]);
    for (int j = 0; j < 8 && traj; j++) { /* dense output where the method has a polynomial */
      double tj = sd.t[n] + sd.h[n] * j / 8.0, xj[4];
      if (j > 0 && fesd_dense_output(it, tj, xj)) continue;
      const double *xb = j == 0 ? sd.x + (size_t)n * sd.nx : xj;
      fprintf(traj, "%.12g,%d,%.12g,%.12g,%.12g,%.12g,%.12g,%.12g\n", tj, k, xb[0], xb[1], xb[2], xb[3], uk[0], uk[1]);
    }
  }
  printf("\n");
  if (traj) {
    const double *xe = sd.x + (size_t)sd.n_elements * sd.nx;
    fprintf(traj, "%.12g,%d,%.12g,%.12g,%.12g,%.12g,%.12g,%.12g\n", t0 + T, k, xe[0], xe[1], xe[2], xe[3], uk[0], uk[1]);
  }
  for (int e = 0; e < nev; e++) {
    printf("    t = %.8f  subsystem %d (c%d = 0)  %s\n", ev[e].t, ev[e].sys, ev[e].sys + 1, kind_name(ev[e].kind));
    if (evf) fprintf(evf, "%.12g,%d,%d,%d,%d\n", ev[e].t, ev[e].sys, (int)ev[e].kind, ev[e].n_before, ev[e].n_after);
  }
  fesd_free(&it);
  return nev;
}

int main(int argc, char **argv) {
  const char *outdir = ".";
  fesd_ocp_settings set;
  fesd_ocp_settings_default(&set);
  set.integrator.n_fe = 6;
  set.integrator.stages = 2; /* Radau IIA (default family) */
  for (int i = 1; i < argc; i++) {
    const char *a = argv[i], *v = i + 1 < argc ? argv[i + 1] : NULL;
    if (!strcmp(a, "--standard")) set.integrator.method = FESD_METHOD_STANDARD;
    else if (!strcmp(a, "--verbose")) set.verbose = 1;
    else if (!strcmp(a, "--family") && v && !fesd_rk_family_parse(v, &set.integrator.family)) i++;
    else if (!strcmp(a, "--stages") && v) set.integrator.stages = atoi(argv[++i]);
    else if (!strcmp(a, "--nfe") && v) set.integrator.n_fe = atoi(argv[++i]);
    else if (!strcmp(a, "--outdir") && v) outdir = argv[++i];
    else if (!strcmp(a, "--hessian") && v) {
      const char *h = argv[++i];
      set.hessian = !strcmp(h, "gn") ? FESD_OCP_HESSIAN_GAUSS_NEWTON : !strcmp(h, "bfgs") ? FESD_OCP_HESSIAN_BFGS
                  : !strcmp(h, "gn-sr1")                                                ? FESD_OCP_HESSIAN_GN_SR1
                                                                                         : FESD_OCP_HESSIAN_AUTO;
    }
    else {
      fprintf(stderr, "usage: ocp_step_eq [--standard] [--family F] [--stages S] [--nfe N] [--outdir DIR] [--hessian auto|gn|bfgs|gn-sr1] [--verbose]\n");
      return 2;
    }
  }
  fesd_problem P;
  fesd_problem_get("ocp-dynamics", &P);
  fesd_ocp_problem op;
  fesd_ocp_step_eq(&op, &P.model);
  fesd_ocp *ocp;
  int st = fesd_ocp_create(&ocp, &op, &set);
  if (st) {
    fprintf(stderr, "ocp_step_eq: %s\n", fesd_status_string(st));
    return 1;
  }
  double ug[2 * NCTRL], x[4 * (NCTRL + 1)], u[2 * NCTRL];
  fesd_ocp_step_eq_guess(ug, NCTRL);
  fesd_ocp_set_guess(ocp, NULL, ug);
  fesd_ocp_info info;
  st = fesd_ocp_solve(ocp, &info);
  fesd_ocp_get_solution(ocp, x, u);
  int nv, ne, ni;
  fesd_ocp_dims(ocp, &nv, &ne, &ni);
  printf("ocp_step_eq: %s, %s s = %d, N_FE = %d, N_ctrl = %d (NLP: %d variables, %d equalities, %d "
         "inequalities)\n",
         set.integrator.method == FESD_METHOD_FESD ? "FESD" : "standard", fesd_rk_family_name(set.integrator.family),
         set.integrator.stages, set.integrator.n_fe, NCTRL, nv, ne, ni);
  printf("status %s: %d SQP iterations, %d QP iterations, %d integrations\n", fesd_status_name(st), info.iterations,
         info.qp_iterations, info.integrations);
  printf("objective %.10f  KKT: stationarity %.1e (relative), feasibility %.1e, complementarity %.1e, min "
         "multiplier %.1e\n",
         info.objective, info.stationarity_rel, info.feasibility, info.complementarity, info.min_multiplier);
  printf("CPU %.1f ms: integration and sensitivities %.1f ms, QP %.1f ms, other %.1f ms\n", 1e3 * info.time_total,
         1e3 * info.time_integration, 1e3 * info.time_qp, 1e3 * info.time_other);
  printf("%5s %10s %10s %10s %10s %10s %10s\n", "k", "q1", "q2", "v1", "v2", "u1", "u2");
  for (int k = 0; k <= NCTRL; k++) {
    printf("%5d %10.5f %10.5f %10.5f %10.5f", k, x[4 * k], x[4 * k + 1], x[4 * k + 2], x[4 * k + 3]);
    if (k < NCTRL) printf(" %10.5f %10.5f", u[2 * k], u[2 * k + 1]);
    printf("\n");
  }
  mkdir(outdir, 0755); /* an existing directory is fine; open_csv reports real failures */
  FILE *traj = open_csv(outdir, "ocp_step_eq_traj.csv", "t,k,q1,q2,v1,v2,u1,u2");
  FILE *el = open_csv(outdir, "ocp_step_eq_elements.csv", "k,n,t,h");
  FILE *evf = open_csv(outdir, "ocp_step_eq_events.csv", "t,sys,kind,n_before,n_after");
  printf("events and element lengths (nominal h = %.4f):\n", 4.0 / NCTRL / set.integrator.n_fe);
  int nev = 0;
  for (int k = 0; k < NCTRL; k++) {
    int n = write_interval(&P, &set.integrator, k, x + 4 * k, u + 2 * k, traj, el, evf);
    if (n < 0) {
      fprintf(stderr, "ocp_step_eq: re-simulation of interval %d failed\n", k);
      return 1;
    }
    nev += n;
  }
  if (traj) fclose(traj);
  if (el) fclose(el);
  if (evf) fclose(evf);
  double xT[4];
  if (fesd_ocp_step_eq_resimulate(&P.model, P.x0, u, NCTRL, 4.0, 40, xT)) {
    fprintf(stderr, "ocp_step_eq: high-accuracy re-simulation failed\n");
    return 1;
  }
  printf("%d switches; high-accuracy re-simulation of the controls: q(4) = (%.10f, %.10f), E(T) = %.2e\n", nev, xT[0],
         xT[1], fesd_ocp_step_eq_error(xT));
  printf("CSV in %s (plots: gnuplot -e \"dir='%s'\" examples/ocp_step_eq.gp)\n", outdir, outdir);
  fesd_ocp_free(&ocp);
  return st == FESD_OK ? 0 : 1;
}
