/* fesd-run: integrate a built-in reference problem (DESIGN.md section 5) and print the
 * result, the error against the exact solution, the detected events and the solver
 * statistics; optionally write the trajectory (element boundaries) as CSV.
 *
 *   fesd-run --problem oscillator --method fesd --family radau --stages 3 --nfe 2 --nsim 40
 *            [--T 1.5708] [--x0 0.1,0.2] [--csv traj.csv] [--sens] [--no-exit-rows] [--quiet]
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fesd.h"
#include "problems/problems.h"

static void usage(void) {
  fprintf(stderr,
          "usage: fesd-run --problem NAME [--method fesd|std] [--family radau|gauss|lobatto3a|"
          "lobatto3c|erk]\n"
          "                [--stages S] [--nfe N] [--nsim N] [--T T] [--x0 a,b,..] [--csv FILE]\n"
          "                [--sens] [--no-exit-rows] [--quiet]\nproblems:");
  for (const char *const *n = fesd_problem_names(); *n; n++) fprintf(stderr, " %s", *n);
  fprintf(stderr, "\n");
}

/* "{0,3}": a list of active modes */
static void print_modes(const int *m, int n) {
  printf("{");
  for (int i = 0; i < n; i++) printf(i ? ",%d" : "%d", m[i]);
  printf("}");
}

static const char *kind_name(fesd_event_kind k) {
  return k == FESD_EVENT_CROSSING ? "crossing" : k == FESD_EVENT_SLIDING_ENTRY ? "sliding-entry" : "sliding-exit";
}

int main(int argc, char **argv) {
  const char *prob = NULL, *csv = NULL, *x0s = NULL;
  fesd_settings set;
  fesd_settings_default(&set);
  int nsim = 20, quiet = 0;
  double T = NAN;
  for (int a = 1; a < argc; a++) {
    const char *k = argv[a], *v = a + 1 < argc ? argv[a + 1] : NULL;
    if (!strcmp(k, "--sens")) {
      set.sensitivities = 1;
      continue;
    }
    if (!strcmp(k, "--no-exit-rows")) {
      set.exit_rows = 0;
      continue;
    }
    if (!strcmp(k, "--quiet")) {
      quiet = 1;
      continue;
    }
    if (!v) {
      usage();
      return 2;
    }
    a++;
    if (!strcmp(k, "--problem")) prob = v;
    else if (!strcmp(k, "--method")) {
      if (!strcmp(v, "fesd")) set.method = FESD_METHOD_FESD;
      else if (!strcmp(v, "std")) set.method = FESD_METHOD_STANDARD;
      else {
        fprintf(stderr, "fesd-run: unknown method '%s' (fesd or std)\n", v);
        return 2;
      }
    } else if (!strcmp(k, "--family")) {
      if (fesd_rk_family_parse(v, &set.family) != FESD_OK) {
        fprintf(stderr, "fesd-run: unknown family '%s'\n", v);
        return 2;
      }
    } else if (!strcmp(k, "--stages")) set.stages = atoi(v);
    else if (!strcmp(k, "--nfe")) set.n_fe = atoi(v);
    else if (!strcmp(k, "--nsim")) nsim = atoi(v);
    else if (!strcmp(k, "--T")) T = atof(v);
    else if (!strcmp(k, "--x0")) x0s = v;
    else if (!strcmp(k, "--csv")) csv = v;
    else {
      usage();
      return 2;
    }
  }
  fesd_problem P;
  if (!prob || fesd_problem_get(prob, &P) != FESD_OK) {
    if (prob) fprintf(stderr, "fesd-run: unknown problem '%s'\n", prob);
    usage();
    return 2;
  }
  if (nsim < 1) {
    fprintf(stderr, "fesd-run: --nsim must be >= 1\n");
    return 2;
  }
  int nx = P.model.nx;
  if (x0s) {
    char *end;
    const char *p = x0s;
    for (int i = 0; i < nx; i++) {
      P.x0[i] = strtod(p, &end);
      if (end == p) {
        fprintf(stderr, "fesd-run: --x0 needs %d comma-separated numbers\n", nx);
        return 2;
      }
      p = *end == ',' ? end + 1 : end;
    }
    P.exact = NULL; /* exact solutions are for the default x0 only */
  }
  if (isfinite(T)) {
    if (!(T > 0)) {
      fprintf(stderr, "fesd-run: --T must be > 0\n");
      return 2;
    }
    P.T = T;
  }
  fesd_integrator *it;
  int st = fesd_create(&it, &P.model, &set);
  if (st) {
    fprintf(stderr, "fesd-run: setup failed: %s (%s)\n", fesd_status_string(st), fesd_status_name(st));
    return 1;
  }
  FILE *out = NULL;
  if (csv && !(out = fopen(csv, "w"))) {
    fprintf(stderr, "fesd-run: cannot write %s\n", csv);
    fesd_free(&it);
    return 1;
  }
  if (out) {
    fprintf(out, "t");
    for (int i = 0; i < nx; i++) fprintf(out, ",x%d", i + 1);
    fprintf(out, ",h,active\n");
  }
  fesd_set_state(it, 0.0, P.x0, P.u);
  int nth;
  fesd_dims(it, &nth, NULL);
  double x[FESD_PROBLEM_MAX_NX];
  for (int k = 0; k < nsim; k++) {
    fesd_step_info info;
    st = fesd_step(it, P.u, P.T / nsim, &info);
    if (st) {
      fprintf(stderr, "fesd-run: step %d failed at t = %.17g: %s (%s)%s%s\n", k, info.failed_time,
              fesd_status_string(st), fesd_status_name(st),
              info.failed_callback ? ", callback " : "", info.failed_callback ? info.failed_callback : "");
      break;
    }
    const fesd_event *ev;
    int ne;
    fesd_last_events(it, &ev, &ne);
    for (int e = 0; e < ne && !quiet; e++) {
      printf("event  t = %.15f  subsystem %d  %-13s modes ", ev[e].t, ev[e].sys, kind_name(ev[e].kind));
      print_modes(ev[e].before, ev[e].n_before);
      printf(" -> ");
      print_modes(ev[e].after, ev[e].n_after);
      printf("\n");
    }
    if (out) {
      fesd_step_data d;
      fesd_last_step_data(it, &d);
      for (int e = 0; e < d.n_elements; e++) {
        fprintf(out, "%.17g", d.t[e]);
        for (int i = 0; i < nx; i++) fprintf(out, ",%.17g", d.x[e * nx + i]);
        unsigned act = 0;
        for (int i = 0; i < nth && i < 32; i++)
          if (d.theta[((size_t)e * d.stages + d.stages - 1) * nth + i] > set.active_tol) act |= 1u << i;
        fprintf(out, ",%.17g,%u\n", d.h[e], act);
      }
    }
  }
  double t;
  fesd_get_state(it, &t, x);
  if (out) {
    fprintf(out, "%.17g", t);
    for (int i = 0; i < nx; i++) fprintf(out, ",%.17g", x[i]);
    fprintf(out, ",,\n");
    fclose(out);
  }
  fesd_stats S;
  fesd_get_stats(it, &S);
  printf("problem %s  method %s  %s s=%d  N_FE=%d  N_sim=%d  T=%.6g\n", P.name,
         set.method == FESD_METHOD_FESD ? "fesd" : "std", fesd_rk_family_name(set.family),
         set.stages, set.n_fe, nsim, P.T);
  printf("x(T) =");
  for (int i = 0; i < nx; i++) printf(" %.16g", x[i]);
  printf("\n");
  if (P.exact && st == FESD_OK) {
    double xe[FESD_PROBLEM_MAX_NX], err = 0;
    P.exact(t, xe);
    for (int i = 0; i < nx; i++) err = fmax(err, fabs(x[i] - xe[i]));
    printf("error |x(T) - exact|_inf = %.3e\n", err);
  }
  if (set.sensitivities && st == FESD_OK) {
    double Sx[FESD_PROBLEM_MAX_NX * FESD_PROBLEM_MAX_NX];
    fesd_get_sensitivities(it, Sx, NULL);
    printf("dx(T)/dx0 =");
    for (int r = 0; r < nx; r++) {
      printf(" [");
      for (int c = 0; c < nx; c++) printf(" %.10g", Sx[c * nx + r]);
      printf(" ]");
    }
    printf("\n");
  }
  printf("steps %d (switch steps %d, splits %d, FB fallbacks %d), Newton iterations %d (ordinary steps: mean %.2f max %.0f;"
         " switch steps: mean %.2f max %.0f), factorizations %d, events %d, time %.3f ms\n",
         S.steps, S.switch_steps, S.splits, S.fallback_steps, S.newton_iter, S.mean_iter_ordinary_step,
         S.max_iter_ordinary_step, S.mean_iter_switch_step, S.max_iter_switch_step, S.factorizations,
         S.events, 1e3 * S.time);
  fesd_free(&it);
  return st == FESD_OK ? 0 : 1;
}
