/* fesd-run: integrate a built-in reference problem (src/problems/problems.c) and print the
 * result, the error against the exact solution, the detected events and the solver
 * statistics; optionally write the trajectory and the events as CSV.
 *
 * Fixed steps (N_sim steps of T / N_sim; --csv: every element boundary):
 *   fesd-run --problem oscillator --method fesd --family radau --stages 3 --nfe 2 --nsim 40
 *            [--T 1.5708] [--x0 0.1,0.2] [--csv traj.csv] [--events ev.csv] [--sens]
 *            [--no-exit-rows] [--quiet]
 * Error-controlled (fesd_integrate; any of --rtol, --atol, --tout; --csv: the output times):
 *   fesd-run --problem oscillator --rtol 1e-8 [--atol 1e-10] [--max-step H]
 *            [--tout 0:2:21 | --tout 0.5,1,1.5] [--csv traj.csv] [--events ev.csv]
 *
 * Exit status: 0 success; 1 the integration or an output file failed; 2 bad arguments
 * (every value is parsed whole, range-checked and must be finite; a message names it).
 */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fesd.h"
#include "problems/problems.h"

#define MAX_NSIM 1000000
#define MAX_NFE 1000 /* as fesd_settings.n_fe */
#define MAX_T 1e6
#define MAX_TOUT 100000

static void usage(FILE *f) {
  fprintf(f,
          "usage: fesd-run --problem NAME [--method fesd|std] [--family radau|gauss|lobatto3a|"
          "lobatto3c|erk]\n"
          "                [--stages S] [--nfe N] [--nsim N] [--T T] [--x0 a,b,..] [--csv FILE]\n"
          "                [--events FILE] [--sens] [--no-exit-rows] [--quiet]\n"
          "                [--rtol R] [--atol A] [--max-step H] [--tout t1,t2,.. | --tout a:b:n]\n"
          "  (--rtol/--atol/--tout: error-controlled steps, fesd_integrate; --csv then holds the\n"
          "   output times, 101 over [0, T] without --tout)\nproblems:");
  for (const char *const *n = fesd_problem_names(); *n; n++) fprintf(f, " %s", *n);
  fprintf(f, "\n");
}

/* The whole of s as an integer in [lo, hi]; otherwise a message and 0. */
static int parse_int(const char *opt, const char *s, long lo, long hi, int *out) {
  char *end;
  errno = 0;
  long v = strtol(s, &end, 10);
  if (end == s || *end || errno == ERANGE || v < lo || v > hi) {
    fprintf(stderr, "fesd-run: %s needs an integer in [%ld, %ld], got '%s'\n", opt, lo, hi, s);
    return 0;
  }
  *out = (int)v;
  return 1;
}

/* One finite number at *p (advanced past it); otherwise a message and 0. */
static int parse_number(const char *opt, const char **p, double *out) {
  char *end;
  double v = strtod(*p, &end);
  if (end == *p) {
    fprintf(stderr, "fesd-run: %s: '%s' is not a number\n", opt, *p);
    return 0;
  }
  if (!isfinite(v)) {
    fprintf(stderr, "fesd-run: %s: %.*s is not finite\n", opt, (int)(end - *p), *p);
    return 0;
  }
  *p = end;
  *out = v;
  return 1;
}

/* T: the whole of s, finite, in (0, MAX_T]. */
static int parse_T(const char *s, double *T) {
  const char *p = s;
  if (!parse_number("--T", &p, T)) return 0;
  if (*p || !(*T > 0 && *T <= MAX_T)) {
    fprintf(stderr, "fesd-run: --T needs a number in (0, %g], got '%s'\n", MAX_T, s);
    return 0;
  }
  return 1;
}

/* x0: exactly nx finite numbers separated by commas. */
static int parse_x0(const char *s, int nx, double *x0) {
  const char *p = s;
  for (int i = 0; i < nx; i++) {
    if (!parse_number("--x0", &p, &x0[i])) return 0;
    if (i + 1 < nx && *p++ != ',') {
      fprintf(stderr, "fesd-run: --x0 needs %d comma-separated numbers, got '%s'\n", nx, s);
      return 0;
    }
  }
  if (*p) {
    fprintf(stderr, "fesd-run: --x0 needs %d comma-separated numbers, got '%s' (extra '%s')\n", nx, s, p);
    return 0;
  }
  return 1;
}

/* "{0,3}": a list of active modes */
static void print_modes(const int *m, int n) {
  printf("{");
  for (int i = 0; i < n; i++) printf(i ? ",%d" : "%d", m[i]);
  printf("}");
}

static const char *kind_name(fesd_event_kind k) {
  static const char *names[] = {"crossing", "sliding-entry", "sliding-exit", "stop"};
  return names[k];
}

/* "0;3": a list of modes for CSV */
static void csv_modes(FILE *out, const int *m, int n) {
  for (int i = 0; i < n; i++) fprintf(out, i ? ";%d" : "%d", m[i]);
}

/* Print (and write as CSV rows: t,subsystem,kind,before,after) n events. */
static void put_events(const fesd_event *ev, int n, int quiet, FILE *out) {
  for (int e = 0; e < n; e++) {
    if (!quiet) {
      printf("event  t = %.15f  subsystem %d  %-13s modes ", ev[e].t, ev[e].sys, kind_name(ev[e].kind));
      print_modes(ev[e].before, ev[e].n_before);
      printf(" -> ");
      print_modes(ev[e].after, ev[e].n_after);
      printf("\n");
    }
    if (out) {
      fprintf(out, "%.17g,%d,%s,", ev[e].t, ev[e].sys, kind_name(ev[e].kind));
      csv_modes(out, ev[e].before, ev[e].n_before);
      fprintf(out, ",");
      csv_modes(out, ev[e].after, ev[e].n_after);
      fprintf(out, "\n");
    }
  }
}

/* A number in [lo, hi] (the whole of s). */
static int parse_range(const char *opt, const char *s, double lo, double hi, double *out) {
  const char *p = s;
  if (!parse_number(opt, &p, out)) return 0;
  if (*p || !(*out >= lo && *out <= hi)) {
    fprintf(stderr, "fesd-run: %s needs a number in [%g, %g], got '%s'\n", opt, lo, hi, s);
    return 0;
  }
  return 1;
}

/* Output times: "a:b:n" (n >= 2 equally spaced from a to b) or increasing "t1,t2,..", all in
 * [0, T]; returns the count (0 after a message). */
static int parse_tout(const char *s, double T, double *t) {
  const char *p = s;
  int n = 0;
  if (strchr(s, ':')) {
    double a, b, c;
    if (!parse_number("--tout", &p, &a) || *p++ != ':' || !parse_number("--tout", &p, &b) || *p++ != ':' ||
        !parse_number("--tout", &p, &c) || *p || c != floor(c) || c < 2 || c > MAX_TOUT || !(a < b)) {
      fprintf(stderr, "fesd-run: --tout a:b:n needs a < b and an integer n in [2, %d], got '%s'\n", MAX_TOUT, s);
      return 0;
    }
    n = (int)c;
    for (int i = 0; i < n; i++) t[i] = i + 1 == n ? b : a + (b - a) * i / (n - 1);
  } else {
    while (1) {
      if (n == MAX_TOUT) {
        fprintf(stderr, "fesd-run: --tout: more than %d times\n", MAX_TOUT);
        return 0;
      }
      if (!parse_number("--tout", &p, &t[n])) return 0;
      if (n > 0 && !(t[n] > t[n - 1])) {
        fprintf(stderr, "fesd-run: --tout times must increase, got '%s'\n", s);
        return 0;
      }
      n++;
      if (!*p) break;
      if (*p++ != ',') {
        fprintf(stderr, "fesd-run: --tout: expected ',' in '%s'\n", s);
        return 0;
      }
    }
  }
  if (!(t[0] >= 0 && t[n - 1] <= T)) {
    fprintf(stderr, "fesd-run: --tout times must lie in [0, T = %g], got '%s'\n", T, s);
    return 0;
  }
  return n;
}

/* One CSV row per element: t, x, h, the active stacked modes of its last stage ("0;3"). */
static void csv_rows(FILE *out, const fesd_step_data *d, int nx, double active_tol) {
  for (int e = 0; e < d->n_elements; e++) {
    fprintf(out, "%.17g", d->t[e]);
    for (int i = 0; i < nx; i++) fprintf(out, ",%.17g", d->x[e * nx + i]);
    fprintf(out, ",%.17g,", d->h[e]);
    const double *th = d->theta + ((size_t)e * d->stages + d->stages - 1) * d->n_theta;
    for (int i = 0, first = 1; i < d->n_theta; i++)
      if (th[i] > active_tol) fprintf(out, first ? "%d" : ";%d", i), first = 0;
    fprintf(out, "\n");
  }
}

/* Options of a run. */
typedef struct {
  const char *csv, *events, *tout;
  int nsim, quiet, adaptive;
  double rtol, atol, max_step;
} run_opts;

/* Open an output file (NULL name: none); 0 after a message. */
static int open_out(const char *name, FILE **f) {
  *f = NULL;
  if (name && !(*f = fopen(name, "w"))) {
    fprintf(stderr, "fesd-run: cannot write %s: %s\n", name, strerror(errno));
    return 0;
  }
  return 1;
}
/* Close an output file; 0 if writing it failed. */
static int close_out(const char *name, FILE *f) {
  if (!f) return 1;
  int werr = ferror(f), cerr = fclose(f);
  if (werr || cerr) fprintf(stderr, "fesd-run: writing %s failed: %s\n", name, strerror(errno));
  return !(werr || cerr);
}

/* Fixed steps: N_sim steps of T / N_sim; the CSV holds every element boundary. */
static int run_fixed(fesd_integrator *it, const fesd_problem *P, const fesd_settings *set, const run_opts *o,
                     FILE *out, FILE *evout) {
  const int nx = P->model.nx;
  if (out) {
    fprintf(out, "t");
    for (int i = 0; i < nx; i++) fprintf(out, ",x%d", i + 1);
    fprintf(out, ",h,active\n");
  }
  int st = FESD_OK;
  for (int k = 0; k < o->nsim; k++) {
    fesd_step_info info;
    st = fesd_step(it, P->u, P->T / o->nsim, &info);
    if (st) {
      fprintf(stderr, "fesd-run: step %d failed at t = %.17g: %s (%s)%s%s; path %s, residual %.2e, last accepted t = %.17g\n",
              k, info.failed_time, fesd_status_string(st), fesd_status_name(st),
              info.failed_callback ? ", callback " : "", info.failed_callback ? info.failed_callback : "",
              info.failed_path ? info.failed_path : "-", info.failed_residual, info.last_time);
      break;
    }
    const fesd_event *ev;
    int ne;
    fesd_last_events(it, &ev, &ne);
    put_events(ev, ne, o->quiet, evout);
    if (out) {
      fesd_step_data d;
      fesd_last_step_data(it, &d);
      csv_rows(out, &d, nx, set->active_tol);
    }
  }
  if (out) {
    double t, x[FESD_PROBLEM_MAX_NX];
    fesd_get_state(it, &t, x);
    fprintf(out, "%.17g", t);
    for (int i = 0; i < nx; i++) fprintf(out, ",%.17g", x[i]);
    fprintf(out, ",,\n");
  }
  return st;
}

/* Error-controlled: fesd_integrate_grid to the output times (default: T, or 101 times with
 * a CSV); the CSV holds the state at each. */
static int run_adaptive(fesd_integrator *it, const fesd_problem *P, const run_opts *o, FILE *out, FILE *evout) {
  const int nx = P->model.nx;
  static double tout[MAX_TOUT];
  int n = 0;
  if (o->tout) {
    if (!(n = parse_tout(o->tout, P->T, tout))) return -1000;
  } else if (out) {
    n = 101;
    for (int i = 0; i < n; i++) tout[i] = i + 1 == n ? P->T : P->T * i / (n - 1);
  } else {
    tout[n++] = P->T;
  }
  fesd_tolerances tol;
  fesd_tolerances_default(&tol);
  if (o->rtol > 0) tol.rtol = o->rtol;
  if (o->atol >= 0) tol.atol = o->atol;
  tol.h_max = o->max_step;
  int st = fesd_set_tolerances(it, &tol);
  if (st) {
    fprintf(stderr, "fesd-run: tolerances refused: %s (%s)\n", fesd_status_string(st), fesd_status_name(st));
    return st;
  }
  double *xout = malloc((size_t)n * nx * sizeof(double));
  if (!xout) return FESD_ERR_NOMEM;
  fesd_integrate_info info;
  st = fesd_integrate_grid(it, P->u, n, tout, xout, &info);
  if (st != FESD_OK) fprintf(stderr, "fesd-run: integration stopped at t = %.17g: %s (%s)\n", info.t,
                             fesd_status_string(st), fesd_status_name(st));
  if (out) {
    fprintf(out, "t");
    for (int i = 0; i < nx; i++) fprintf(out, ",x%d", i + 1);
    fprintf(out, "\n");
    for (int k = 0; k < info.n_done; k++) {
      fprintf(out, "%.17g", tout[k]);
      for (int i = 0; i < nx; i++) fprintf(out, ",%.17g", xout[(size_t)k * nx + i]);
      fprintf(out, "\n");
    }
  }
  free(xout);
  const fesd_event *ev;
  int ne;
  fesd_event_log(it, &ev, &ne);
  put_events(ev, ne, o->quiet, evout);
  printf("adaptive: rtol %.1e atol %.1e: steps %d (switch steps %d), rejected %d, failed attempts %d, %d output times\n",
         tol.rtol, tol.atol, info.steps, info.switch_steps, info.rejected, info.failed_attempts, info.n_done);
  return st;
}

int main(int argc, char **argv) {
  const char *prob = NULL, *x0s = NULL;
  fesd_settings set;
  fesd_settings_default(&set);
  run_opts o = {.nsim = 20, .rtol = -1, .atol = -1};
  double T = NAN;
  for (int a = 1; a < argc; a++) {
    const char *k = argv[a], *v = a + 1 < argc ? argv[a + 1] : NULL;
    if (!strcmp(k, "--help") || !strcmp(k, "-h")) {
      usage(stdout);
      return 0;
    }
    if (!strcmp(k, "--sens")) {
      set.sensitivities = 1;
      continue;
    }
    if (!strcmp(k, "--no-exit-rows")) {
      set.exit_rows = 0;
      continue;
    }
    if (!strcmp(k, "--quiet")) {
      o.quiet = 1;
      continue;
    }
    if (strncmp(k, "--", 2) || !strcmp(k, "--")) {
      fprintf(stderr, "fesd-run: unexpected argument '%s'\n", k);
      usage(stderr);
      return 2;
    }
    if (!v) {
      fprintf(stderr, "fesd-run: %s needs a value\n", k);
      usage(stderr);
      return 2;
    }
    a++;
    int ok = 1;
    if (!strcmp(k, "--problem")) prob = v;
    else if (!strcmp(k, "--method")) {
      if (!strcmp(v, "fesd")) set.method = FESD_METHOD_FESD;
      else if (!strcmp(v, "std")) set.method = FESD_METHOD_STANDARD;
      else {
        fprintf(stderr, "fesd-run: unknown method '%s' (fesd or std)\n", v);
        ok = 0;
      }
    } else if (!strcmp(k, "--family")) {
      if (fesd_rk_family_parse(v, &set.family) != FESD_OK) {
        fprintf(stderr, "fesd-run: unknown family '%s'\n", v);
        ok = 0;
      }
    } else if (!strcmp(k, "--stages")) ok = parse_int(k, v, 1, FESD_RK_MAX_STAGES, &set.stages);
    else if (!strcmp(k, "--nfe")) ok = parse_int(k, v, 1, MAX_NFE, &set.n_fe);
    else if (!strcmp(k, "--nsim")) ok = parse_int(k, v, 1, MAX_NSIM, &o.nsim);
    else if (!strcmp(k, "--T")) ok = parse_T(v, &T);
    else if (!strcmp(k, "--x0")) x0s = v; /* parsed once the problem (and nx) is known */
    else if (!strcmp(k, "--csv")) o.csv = v;
    else if (!strcmp(k, "--events")) o.events = v;
    else if (!strcmp(k, "--rtol")) ok = parse_range(k, v, 1e-14, 0.5, &o.rtol), o.adaptive = 1;
    else if (!strcmp(k, "--atol")) ok = parse_range(k, v, 0, 1e300, &o.atol), o.adaptive = 1;
    else if (!strcmp(k, "--max-step")) ok = parse_range(k, v, 0, MAX_T, &o.max_step), o.adaptive = 1;
    else if (!strcmp(k, "--tout")) o.tout = v, o.adaptive = 1; /* parsed once T is known */
    else {
      fprintf(stderr, "fesd-run: unknown option '%s'\n", k);
      usage(stderr);
      return 2;
    }
    if (!ok) return 2;
  }
  fesd_problem P;
  if (!prob || fesd_problem_get(prob, &P) != FESD_OK) {
    if (prob) fprintf(stderr, "fesd-run: unknown problem '%s'\n", prob);
    else fprintf(stderr, "fesd-run: --problem is required\n");
    usage(stderr);
    return 2;
  }
  if (set.method == FESD_METHOD_FESD && set.n_fe < 2) {
    fprintf(stderr, "fesd-run: --nfe must be >= 2 with --method fesd (a switch needs an element boundary)\n");
    return 2;
  }
  const int nx = P.model.nx;
  if (x0s) {
    if (!parse_x0(x0s, nx, P.x0)) return 2;
    P.exact = NULL; /* exact solutions are for the default x0 only */
  }
  if (!isnan(T)) P.T = T;
  fesd_integrator *it;
  int st = fesd_create(&it, &P.model, &set);
  if (st) {
    fprintf(stderr, "fesd-run: setup failed: %s (%s)\n", fesd_status_string(st), fesd_status_name(st));
    /* a family/stage combination or a setting the library refuses is an argument error */
    return st == FESD_ERR_INVALID_ARG || st == FESD_ERR_UNSUPPORTED_TABLEAU ? 2 : 1;
  }
  if ((st = fesd_set_state(it, 0.0, P.x0, P.u))) {
    fprintf(stderr, "fesd-run: initial state refused: %s (%s)\n", fesd_status_string(st), fesd_status_name(st));
    fesd_free(&it);
    return 1;
  }
  FILE *out, *evout = NULL;
  if (!open_out(o.csv, &out) || !open_out(o.events, &evout)) {
    if (out) fclose(out);
    fesd_free(&it);
    return 1;
  }
  if (evout) fprintf(evout, "t,subsystem,kind,before,after\n");
  st = o.adaptive ? run_adaptive(it, &P, &o, out, evout) : run_fixed(it, &P, &set, &o, out, evout);
  int io = !close_out(o.csv, out) | !close_out(o.events, evout); /* a failed output fails the run */
  if (st == -1000) { /* bad --tout */
    fesd_free(&it);
    return 2;
  }
  double t, x[FESD_PROBLEM_MAX_NX];
  fesd_get_state(it, &t, x);
  fesd_stats S;
  fesd_get_stats(it, &S);
  printf("problem %s  method %s  %s s=%d  N_FE=%d  ", P.name, set.method == FESD_METHOD_FESD ? "fesd" : "std",
         fesd_rk_family_name(set.family), set.stages, set.n_fe);
  if (o.adaptive) printf("adaptive  T=%.6g\n", P.T);
  else printf("N_sim=%d  T=%.6g\n", o.nsim, P.T);
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
  if (S.coarse_steps || S.nonunique_steps || S.sens_inaccurate_steps || S.exit_not_pinned_steps)
    printf("flagged steps: %d too coarse (local error estimate above coarse_tol), %d non-unique start, "
           "%d inaccurate sensitivities, %d unpinned exits\n", S.coarse_steps, S.nonunique_steps,
           S.sens_inaccurate_steps, S.exit_not_pinned_steps);
  fesd_free(&it);
  if (fflush(stdout) || ferror(stdout)) {
    fprintf(stderr, "fesd-run: writing the standard output failed: %s\n", strerror(errno));
    io = 1;
  }
  return st == FESD_OK && !io ? 0 : 1;
}
