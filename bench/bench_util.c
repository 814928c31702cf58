#include "bench_util.h"

#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>

bench_options bench_opt = {0, "bench/results", 0.2, 5};

int bench_init(int argc, char **argv, const char *usage) {
  for (int i = 1; i < argc; i++) {
    if (!strcmp(argv[i], "--quick")) {
      bench_opt.quick = 1;
    } else if (argv[i][0] != '-') {
      bench_opt.outdir = argv[i];
    } else {
      fprintf(stderr, "usage: %s [--quick] [OUTDIR]\n%s\n", argv[0], usage);
      return 1;
    }
  }
  if (bench_opt.quick) bench_opt.min_time = 0.01, bench_opt.reps = 3;
  if (mkdir(bench_opt.outdir, 0755) != 0 && errno != EEXIST) {
    perror(bench_opt.outdir);
    return 1;
  }
  return 0;
}

FILE *bench_csv(const char *name, const char *header) {
  char path[1024];
  snprintf(path, sizeof path, "%s/%s", bench_opt.outdir, name);
  FILE *f = fopen(path, "w");
  if (!f) {
    perror(path);
    return NULL;
  }
  fprintf(f, "%s\n", header);
  return f;
}

double bench_cpu(void) {
  struct timespec t;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

static int cmp_double(const void *a, const void *b) {
  double x = *(const double *)a, y = *(const double *)b;
  return (x > y) - (x < y);
}

double bench_median(double *v, int n) {
  qsort(v, (size_t)n, sizeof *v, cmp_double);
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

/* CPU seconds per call of fn over >= t_min seconds (negative if fn fails) */
static double time_calls(bench_fn fn, void *ctx, double t_min) {
  long count = 0;
  double t0 = bench_cpu(), el;
  do {
    if (fn(ctx)) return -1.0;
    count++;
    el = bench_cpu() - t0;
  } while (el < t_min);
  return el / (double)count;
}

double bench_time(bench_fn fn, void *ctx) {
  double per[16];
  int reps = bench_opt.reps > 16 ? 16 : bench_opt.reps;
  if (fn(ctx)) return NAN; /* warm-up: first-touch of workspaces, caches */
  for (int r = 0; r < reps; r++)
    if ((per[r] = time_calls(fn, ctx, bench_opt.min_time)) < 0) return NAN;
  return bench_median(per, reps);
}

double bench_time_pair(bench_fn a, void *ca, bench_fn b, void *cb, double *ta, double *tb) {
  enum { MAX_ROUNDS = 33 };
  double va[MAX_ROUNDS], vb[MAX_ROUNDS], ratio[MAX_ROUNDS];
  int rounds = 2 * bench_opt.reps + 1;
  if (rounds > MAX_ROUNDS) rounds = MAX_ROUNDS;
  *ta = *tb = NAN;
  if (a(ca) || b(cb)) return NAN; /* warm-up */
  for (int r = 0; r < rounds; r++) {
    va[r] = time_calls(a, ca, 0.25 * bench_opt.min_time);
    vb[r] = time_calls(b, cb, 0.25 * bench_opt.min_time);
    if (va[r] < 0 || vb[r] < 0) return NAN;
    ratio[r] = vb[r] / va[r];
  }
  *ta = bench_median(va, rounds);
  *tb = bench_median(vb, rounds);
  return bench_median(ratio, rounds);
}

int bench_integrate(const bench_job *j, bench_run *r) {
  const fesd_problem *P = j->P;
  int st = fesd_set_state(j->it, 0.0, P->x0, P->u);
  if (r) {
    memset(r, 0, sizeof *r);
    r->err = NAN;
  }
  fesd_step_info info;
  for (int k = 0; k < j->nsim && !st; k++) {
    st = fesd_step(j->it, P->u, j->T / j->nsim, &info);
    if (!r || st) continue;
    if (info.residual > r->max_residual) r->max_residual = info.residual;
    const fesd_event *ev;
    int ne;
    fesd_last_events(j->it, &ev, &ne);
    for (int e = 0; e < ne && r->n_events < 16; e++) {
      r->ev_t[r->n_events] = ev[e].t;
      r->ev_kind[r->n_events++] = (int)ev[e].kind;
    }
  }
  if (!r) return st;
  r->status = st;
  fesd_get_state(j->it, NULL, r->xT);
  fesd_get_stats(j->it, &r->stats);
  double xe[FESD_PROBLEM_MAX_NX];
  if (!st && P->exact && P->exact(j->T, xe) == 0) {
    r->err = 0;
    for (int i = 0; i < P->model.nx; i++) r->err = fmax(r->err, fabs(r->xT[i] - xe[i]));
  }
  return st;
}

int bench_integrate_fn(void *ctx) { return bench_integrate((const bench_job *)ctx, NULL); }

double bench_event_near(const bench_run *r, double t, int kind) {
  double best = NAN;
  for (int e = 0; e < r->n_events; e++)
    if ((kind < 0 || r->ev_kind[e] == kind) && !(fabs(r->ev_t[e] - t) >= fabs(best - t))) best = r->ev_t[e];
  return best;
}

fesd_integrator *bench_create(const fesd_problem *P, const fesd_settings *s) {
  fesd_integrator *it = NULL;
  int st = fesd_create(&it, &P->model, s);
  if (st) fprintf(stderr, "%s: fesd_create: %s\n", P->name, fesd_status_string(st));
  return it;
}

double bench_slope(const double *x, const double *y, int n, double lo, double hi, int *used) {
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  int m = 0;
  for (int i = 0; i < n; i++) {
    if (!(y[i] > lo) || !(y[i] < hi) || !(x[i] > 0)) continue;
    double lx = log(x[i]), ly = log(y[i]);
    sx += lx, sy += ly, sxx += lx * lx, sxy += lx * ly, m++;
  }
  if (used) *used = m;
  return m < 3 ? NAN : (m * sxy - sx * sy) / (m * sxx - sx * sx);
}

static int cmp_point_time(const void *a, const void *b) {
  double x = ((const bench_point *)a)->t, y = ((const bench_point *)b)->t;
  return (x > y) - (x < y);
}

int bench_front(const bench_point *p, int n, bench_point *f) {
  bench_point tmp[512];
  int m = 0, k = 0;
  for (int i = 0; i < n && m < 512; i++)
    if (isfinite(p[i].t) && isfinite(p[i].e)) tmp[m++] = (bench_point){p[i].t, fmax(p[i].e, 1e-16), p[i].id};
  qsort(tmp, (size_t)m, sizeof *tmp, cmp_point_time);
  for (int i = 0; i < m; i++)
    if (k == 0 || tmp[i].e < f[k - 1].e) f[k++] = tmp[i];
  return k;
}

double bench_front_err(const bench_point *f, int k, double t) {
  if (k == 0 || t < f[0].t) return NAN;
  for (int i = 0; i + 1 < k; i++)
    if (t <= f[i + 1].t) {
      double a = log(t / f[i].t) / log(f[i + 1].t / f[i].t);
      return exp((1 - a) * log(f[i].e) + a * log(f[i + 1].e));
    }
  return f[k - 1].e;
}

double bench_front_time(const bench_point *f, int k, double e) {
  for (int i = 0; i < k; i++)
    if (f[i].e <= e) {
      if (i == 0) return f[0].t;
      double a = log(e / f[i - 1].e) / log(f[i].e / f[i - 1].e);
      return exp((1 - a) * log(f[i - 1].t) + a * log(f[i].t));
    }
  return NAN;
}
