/* Shared helpers of the bench programs: command line, CPU timing that survives a
 * noisy machine, CSV output, and one integration of a reference problem.
 *
 * Timing: CLOCK_THREAD_CPUTIME_ID (other processes do not count); a repetition calls
 * the function until >= min_time CPU seconds have elapsed and yields the time per call;
 * the result is the median over reps repetitions (full: 0.2 s x 5, --quick: 0.01 s x 3). */
#ifndef FESD_BENCH_UTIL_H
#define FESD_BENCH_UTIL_H

#include <stdio.h>

#include "fesd.h"
#include "problems/problems.h"

typedef struct {
  int quick;          /* --quick: small grids, short timings (CI) */
  const char *outdir; /* CSV directory (default bench/results) */
  double min_time;    /* CPU seconds per repetition */
  int reps;           /* repetitions (median) */
} bench_options;

extern bench_options bench_opt;

/* Parse [--quick] [OUTDIR]; returns 0 or prints usage and returns 1. */
int bench_init(int argc, char **argv, const char *usage);
/* Open OUTDIR/name for writing and write the header line (NULL on error, reported). */
FILE *bench_csv(const char *name, const char *header);
/* CPU seconds of this thread. */
double bench_cpu(void);

/* Median CPU seconds per call of fn (see above); NaN if fn returns nonzero. */
typedef int (*bench_fn)(void *ctx);
double bench_time(bench_fn fn, void *ctx);
double bench_median(double *v, int n); /* sorts v */
/* Paired timing of two functions, for ratios that must not depend on when each was
 * measured (the machine's speed drifts by tens of percent over seconds): rounds alternate
 * a and b (each for >= min_time / 4 CPU seconds); returns the median over the rounds of
 * time(b) / time(a), and the median times per call in *ta, *tb. NaN if a call fails. */
double bench_time_pair(bench_fn a, void *ca, bench_fn b, void *cb, double *ta, double *tb);

/* One integration: nsim steps of T / nsim from P->x0 with P->u. */
typedef struct {
  int status;
  double err;        /* max_i |x_i(T) - exact_i(T)| (NaN without exact solution) */
  double xT[FESD_PROBLEM_MAX_NX];
  double max_residual; /* max over the steps of the final ||F||_inf */
  int n_events;
  double ev_t[16];
  int ev_kind[16];
  fesd_stats stats;
} bench_run;

typedef struct {
  fesd_integrator *it;
  const fesd_problem *P;
  int nsim;
  double T;
} bench_job;

/* Run the job and record (r may be NULL: no recording, as in timed loops). */
int bench_integrate(const bench_job *j, bench_run *r);
/* bench_fn wrapper of bench_integrate(ctx, NULL). */
int bench_integrate_fn(void *ctx);
/* Event time nearest to t (NaN if none), optionally of one kind (-1: any). */
double bench_event_near(const bench_run *r, double t, int kind);

/* Create an integrator for P with settings (reports failures to stderr). */
fesd_integrator *bench_create(const fesd_problem *P, const fesd_settings *s);

/* Pareto fronts of (CPU time, error) points: the front is increasing in time, decreasing
 * in error; errors below 1e-16 (exact results) count as 1e-16; points with a NaN are left
 * out. bench_front writes at most n points to f (n <= 512) and returns their number. */
typedef struct {
  double t, e;
  int id; /* the caller's index of the point */
} bench_point;
int bench_front(const bench_point *p, int n, bench_point *f);
/* Front error at time t, log-log interpolated (NaN before the first point; constant after
 * the last: more time cannot hurt). */
double bench_front_err(const bench_point *f, int k, double t);
/* First time at which the front reaches error e, log-log interpolated (NaN if never). */
double bench_front_time(const bench_point *f, int k, double e);

/* Least-squares slope of log y against log x over the points with lo < y < hi; *used
 * gets the number of points; NaN below 3 points. */
double bench_slope(const double *x, const double *y, int n, double lo, double hi, int *used);

#endif
