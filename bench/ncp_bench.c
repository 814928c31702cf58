/* ncp_bench: solve time and iterations of the FB semismooth Newton solver vs size,
 * for every backend, on random LCPs w = M z + q (known solution, cold start z0 = 1).
 *   random  : 5 off-diagonal entries per row at random columns (sparse-ish, but the
 *             LU fill of a random graph is large)
 *   banded  : block-tridiagonal M with dense 8 x 8 blocks (24 entries per row)
 *   blocks  : block lower-bidiagonal M with dense 30 x 30 blocks, the shape of an FESD
 *             step (finite elements of ~30 unknowns, each coupled to the previous one)
 *   dense   : full M
 *   lsq     : banded LCP plus n/10 consistent smooth rows (m > n, Levenberg-Marquardt)
 * Timing: median over repeats of one full solve, repeated until >= 0.2 s elapsed
 * (at least 3 repeats unless one solve takes > 1 s). A (family, backend) column
 * stops growing once one solve exceeds 3 s.
 * Output: a table on stdout and CSV (default bench/results/ncp_backends.csv, or argv[1]).
 * Usage: ncp_bench [csv-path] [max-n]   */
#include "fesd_ncp.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>

static double now(void) {
  struct timespec t;
  clock_gettime(CLOCK_MONOTONIC, &t);
  return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

typedef struct {
  unsigned long long s;
} rng_t;
static double rnd(rng_t *r) { /* xorshift64*, uniform [0, 1) */
  r->s ^= r->s >> 12;
  r->s ^= r->s << 25;
  r->s ^= r->s >> 27;
  return (double)((r->s * 2685821657736338717ULL) >> 11) * (1.0 / 9007199254740992.0);
}

/* LCP in CSR plus n_extra smooth rows e_j = z_{c_j} - z*_{c_j} (consistent). */
typedef struct {
  int n, nnz_m, n_extra;
  int *rp, *ci;
  double *v, *q, *zs;
  int *row, *col, nnz;
} lcp_t;

static int lcp_eval(const double *z, double *raw, double *jac, void *user) {
  const lcp_t *p = (const lcp_t *)user;
  const int n = p->n, ne = p->n_extra;
  for (int j = 0; j < ne; j++) raw[j] = z[(j * 7) % n] - p->zs[(j * 7) % n];
  for (int k = 0; k < n; k++) raw[ne + k] = z[k];
  for (int i = 0; i < n; i++) {
    double s = p->q[i];
    for (int k = p->rp[i]; k < p->rp[i + 1]; k++) s += p->v[k] * z[p->ci[k]];
    raw[ne + n + i] = s;
  }
  if (jac) {
    for (int t = 0; t < ne + n; t++) jac[t] = 1.0;
    memcpy(jac + ne + n, p->v, (size_t)p->nnz_m * sizeof(double));
  }
  return 0;
}

static void lcp_free(lcp_t *p) {
  free(p->rp);
  free(p->ci);
  free(p->v);
  free(p->q);
  free(p->zs);
  free(p->row);
  free(p->col);
}

enum { RANDOM, BANDED, BLOCKS, DENSE };

/* Diagonally dominant M (a P-matrix) with the pattern of the family. */
static void lcp_make(lcp_t *p, int n, int family, int n_extra, unsigned long long seed) {
  rng_t r = {seed * 0x9E3779B97F4A7C15ULL + 7};
  const int bs = family == BANDED ? 8 : 30;
  const int per_row = family == RANDOM ? 6 : family == BANDED ? 3 * bs : family == BLOCKS ? 2 * bs : n;
  memset(p, 0, sizeof *p);
  p->n = n;
  p->n_extra = n_extra;
  p->rp = malloc((size_t)(n + 1) * sizeof(int));
  p->ci = malloc((size_t)n * per_row * sizeof(int));
  p->v = malloc((size_t)n * per_row * sizeof(double));
  int k = 0;
  for (int i = 0; i < n; i++) {
    p->rp[i] = k;
    int first = k;
    double sum = 0.0;
    if (family == RANDOM) {
      int cols[6], nc = 0;
      cols[nc++] = i;
      while (nc < 6 && nc < n) {
        int c = (int)(rnd(&r) * n), dup = 0;
        for (int t = 0; t < nc; t++) dup |= cols[t] == c;
        if (!dup) cols[nc++] = c;
      }
      for (int a = 1; a < nc; a++) /* sorted columns */
        for (int b = a; b > 0 && cols[b] < cols[b - 1]; b--) {
          int t = cols[b];
          cols[b] = cols[b - 1];
          cols[b - 1] = t;
        }
      for (int t = 0; t < nc; t++) p->ci[k++] = cols[t];
    } else {
      int blk = i / bs, lo = family == DENSE ? 0 : (blk - 1) * bs;
      int hi = family == DENSE ? n : family == BANDED ? (blk + 2) * bs : (blk + 1) * bs;
      for (int c = lo < 0 ? 0 : lo; c < (hi > n ? n : hi); c++) p->ci[k++] = c;
    }
    for (int t = first; t < k; t++) {
      p->v[t] = p->ci[t] == i ? 0.0 : 2.0 * rnd(&r) - 1.0;
      sum += fabs(p->v[t]);
    }
    for (int t = first; t < k; t++)
      if (p->ci[t] == i) p->v[t] = sum + 0.5 + rnd(&r);
  }
  p->rp[n] = k;
  p->nnz_m = k;
  p->zs = malloc((size_t)n * sizeof(double));
  p->q = malloc((size_t)n * sizeof(double));
  for (int i = 0; i < n; i++) {
    int pos = rnd(&r) < 0.5;
    p->zs[i] = pos ? 0.5 + rnd(&r) : 0.0;
    p->q[i] = pos ? 0.0 : 0.5 + rnd(&r); /* w*_i; M z* is subtracted below */
  }
  for (int i = 0; i < n; i++)
    for (int t = p->rp[i]; t < p->rp[i + 1]; t++) p->q[i] -= p->v[t] * p->zs[p->ci[t]];
  p->nnz = n_extra + n + k;
  p->row = malloc((size_t)p->nnz * sizeof(int));
  p->col = malloc((size_t)p->nnz * sizeof(int));
  int t = 0;
  for (int j = 0; j < n_extra; j++) {
    p->row[t] = j;
    p->col[t++] = (j * 7) % n;
  }
  for (int i = 0; i < n; i++) {
    p->row[t] = n_extra + i;
    p->col[t++] = i;
  }
  for (int i = 0; i < n; i++)
    for (int c = p->rp[i]; c < p->rp[i + 1]; c++) {
      p->row[t] = n_extra + n + i;
      p->col[t++] = p->ci[c];
    }
}

static int cmp_double(const void *a, const void *b) {
  double x = *(const double *)a, y = *(const double *)b;
  return (x > y) - (x < y);
}

typedef struct {
  int status, iterations, factorizations, evals, repeats;
  double median, linsolve;
} result_t;

static result_t run(const lcp_t *p, int backend) {
  result_t res = {0};
  fesd_ncp_problem pr = {p->n, p->n_extra, p->n, p->nnz, p->row, p->col, lcp_eval, (void *)p};
  fesd_ncp_settings s;
  fesd_ncp_settings_default(&s);
  s.backend = backend;
  fesd_ncp *ws = NULL;
  res.status = fesd_ncp_setup(&ws, &pr, &s);
  if (res.status != FESD_OK) return res;
  enum { MAX_REPS = 1 << 17 }; /* 0.2 s of the smallest problem fits */
  double *z = malloc((size_t)p->n * sizeof(double));
  double *times = malloc(MAX_REPS * sizeof(double)), *lin = malloc(MAX_REPS * sizeof(double));
  double t_start = now();
  int reps = 0;
  while (reps < MAX_REPS) {
    for (int i = 0; i < p->n; i++) z[i] = 1.0;
    fesd_ncp_info info;
    double t0 = now();
    res.status = fesd_ncp_solve(ws, z, 0.0, &info);
    times[reps] = now() - t0;
    lin[reps++] = info.time_linsolve;
    res.iterations = info.iterations;
    res.factorizations = info.factorizations;
    res.evals = info.evals;
    double err = 0.0;
    for (int i = 0; i < p->n; i++) err = fmax(err, fabs(z[i] - p->zs[i]));
    if (res.status == FESD_OK && err > 1e-8) res.status = -999; /* wrong solution */
    if (res.status != FESD_OK) break;
    double el = now() - t_start;
    if (el >= 0.2 && (reps >= 3 || times[0] > 1.0)) break;
  }
  qsort(times, (size_t)reps, sizeof(double), cmp_double);
  qsort(lin, (size_t)reps, sizeof(double), cmp_double);
  res.median = times[reps / 2];
  res.linsolve = lin[reps / 2];
  res.repeats = reps;
  free(z);
  free(times);
  free(lin);
  fesd_ncp_free(&ws);
  return res;
}

int main(int argc, char **argv) {
  const char *csv_path = argc > 1 ? argv[1] : "bench/results/ncp_backends.csv";
  int max_n = argc > 2 ? atoi(argv[2]) : 5000;
  const int sizes[] = {10, 20, 30, 50, 75, 100, 150, 200, 300, 500, 1000, 2000, 5000};
  struct {
    const char *name;
    int family, lsq, max_n;
  } fams[] = {{"random", RANDOM, 0, 5000}, {"banded", BANDED, 0, 5000},
              {"blocks", BLOCKS, 0, 5000}, {"dense", DENSE, 0, 2000},
              {"lsq", BANDED, 1, 5000}};
  const int nfam = (int)(sizeof fams / sizeof fams[0]);
  const int sq_backends[] = {FESD_NCP_BACKEND_DENSE, FESD_NCP_BACKEND_UMFPACK,
                             FESD_NCP_BACKEND_KLU, FESD_NCP_BACKEND_CHOLMOD};
  const int lsq_backends[] = {FESD_NCP_BACKEND_DENSE, FESD_NCP_BACKEND_CHOLMOD};

  char dir[4096]; /* create the CSV's directory (best effort) */
  snprintf(dir, sizeof dir, "%s", csv_path);
  char *slash = strrchr(dir, '/');
  if (slash) {
    *slash = '\0';
    mkdir(dir, 0755);
  }
  FILE *csv = fopen(csv_path, "w");
  if (!csv) fprintf(stderr, "ncp_bench: cannot write %s; table only\n", csv_path);
  if (csv)
    fprintf(csv, "family,n,m,nnz_jac,backend,status,iterations,factorizations,evals,repeats,"
                 "median_solve_s,median_linsolve_s,per_iteration_s\n");
  printf("FB semismooth Newton, cold start z0 = 1, median solve time [ms] (iterations)\n");
  printf("%-7s %6s %8s", "family", "n", "nnz(J)");
  for (int b = 0; b < 4; b++) printf(" %16s", fesd_ncp_backend_name(sq_backends[b]));
  printf("\n");

  for (int f = 0; f < nfam; f++) {
    int stopped[5] = {0}, sparse_wins[16] = {0}, measured = 0;
    const int lsq = fams[f].lsq, *bk = lsq ? lsq_backends : sq_backends, nb = lsq ? 2 : 4;
    for (size_t si = 0; si < sizeof sizes / sizeof sizes[0]; si++) {
      int n = sizes[si];
      if (n > max_n || n > fams[f].max_n) break;
      lcp_t p;
      lcp_make(&p, n, fams[f].family, lsq ? n / 10 : 0, 17 + si);
      printf("%-7s %6d %8d", fams[f].name, n, p.nnz);
      double best_sparse = INFINITY, dense_t = INFINITY;
      for (int b = 0; b < nb; b++) {
        if (stopped[b]) {
          printf(" %16s", "-");
          continue;
        }
        result_t r = run(&p, bk[b]);
        if (r.status != FESD_OK) {
          printf(" %16s", fesd_status_name(r.status));
        } else {
          printf(" %10.3f (%2d) ", 1e3 * r.median, r.iterations);
        }
        fflush(stdout);
        if (csv)
          fprintf(csv, "%s,%d,%d,%d,%s,%d,%d,%d,%d,%d,%.6e,%.6e,%.6e\n", fams[f].name, n,
                  n + p.n_extra, p.nnz, fesd_ncp_backend_name(bk[b]), r.status, r.iterations,
                  r.factorizations, r.evals, r.repeats, r.median, r.linsolve,
                  r.iterations ? r.median / r.iterations : 0.0);
        if (r.status == FESD_OK) {
          if (bk[b] == FESD_NCP_BACKEND_DENSE) dense_t = r.median;
          else if (lsq || bk[b] != FESD_NCP_BACKEND_CHOLMOD)
            best_sparse = fmin(best_sparse, r.median);
        }
        if (r.status != FESD_OK || r.median > 3.0) stopped[b] = 1;
      }
      printf("\n");
      sparse_wins[si] = best_sparse < dense_t;
      measured = (int)si + 1;
      lcp_free(&p);
    }
    /* crossover: smallest n from which a sparse backend stays faster */
    int crossover = -1;
    for (int si = measured - 1; si >= 0 && sparse_wins[si]; si--) crossover = sizes[si];
    if (crossover > 0)
      printf("  %s: a sparse backend is faster than dense from n = %d on\n", fams[f].name,
             crossover);
    else
      printf("  %s: dense fastest at every measured n\n", fams[f].name);
  }
  if (csv) {
    fclose(csv);
    printf("CSV written to %s\n", csv_path);
  }
  return 0;
}
