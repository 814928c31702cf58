/* Cost of an ordinary step (one without a switch, event, fallback or split) per problem:
 * instructions under callgrind, and CPU time per integration.
 *
 *   bench_step_cost list                 the cases, one per line
 *   bench_step_cost steps CASE K         run CASE; collect (callgrind client requests) only
 *                                        during K consecutive ordinary steps
 *   bench_step_cost phases PROB S NSIM   integrate PROB (fixed steps T / NSIM); under callgrind
 *                                        --collect-atstart=no one dump per phase: create (with
 *                                        set_state), each step (named with its kind), free
 *   bench_step_cost states               final state of every case (%a: a change of the
 *                                        results shows bit for bit)
 *   bench_step_cost cpu [OUTDIR]         CPU time per integration of every case (bench_time):
 *                                        OUTDIR/step_cpu.csv
 *
 * tools/step_cost.sh runs `steps` under valgrind --tool=callgrind --collect-atstart=no for two
 * K and takes (I(K2) - I(K1)) / (K2 - K1): instructions per ordinary step, free of the
 * first-step effects of the window. The window is the first run of K ordinary steps from step
 * 2 on, found by a dry run of an identical integrator (the integrator is deterministic). */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <valgrind/callgrind.h>

#include "bench_util.h"
#include "problems/friction_chain.h"

typedef struct {
  const char *name, *prob; /* prob "chain": the friction chain, n = 16, every mass slipping */
  int s, nsim;
} step_case;

static const step_case cases[] = {
    {"oscillator-s3", "oscillator", 3, 40}, {"oscillator-s4", "oscillator", 4, 40},
    {"oscillator-s5", "oscillator", 5, 40}, {"sign-c-s2", "sign-c", 2, 40},
    {"ocp-dynamics-s2", "ocp-dynamics", 2, 40}, {"stick-slip-s3", "stick-slip", 3, 200},
    {"chain16-s2", "chain", 2, 40}};
#define N_CASES ((int)(sizeof cases / sizeof cases[0]))
#define MAX_STEPS 400

typedef struct {
  fesd_problem P;
  fesd_friction_chain fc;
  int chain;
  const fesd_model *model;
  const double *x0, *u;
  double h;
} setup;

static int make(const step_case *c, setup *S) {
  memset(S, 0, sizeof *S);
  if (!strcmp(c->prob, "chain")) {
    if (fesd_friction_chain_init(&S->fc, 16, 5.0)) return 1;
    S->chain = 1;
    S->model = &S->fc.model;
    S->x0 = S->fc.x0;
    S->h = 0.2;
    return 0;
  }
  if (fesd_problem_get(c->prob, &S->P)) return 1;
  S->model = &S->P.model;
  S->x0 = S->P.x0;
  S->u = S->P.u;
  S->h = S->P.T / c->nsim;
  return 0;
}

static void unmake(setup *S) {
  if (S->chain) fesd_friction_chain_free(&S->fc);
}

static fesd_integrator *create(const step_case *c, const setup *S) {
  fesd_settings set;
  fesd_settings_default(&set);
  set.stages = c->s;
  fesd_integrator *it = NULL;
  if (fesd_create(&it, S->model, &set)) return NULL;
  if (fesd_set_state(it, 0.0, S->x0, S->u)) fesd_free(&it);
  return it;
}

static int ordinary(fesd_integrator *it, const fesd_step_info *in) {
  const fesd_event *ev;
  int ne;
  fesd_last_events(it, &ev, &ne);
  return !in->switch_step && !ne && !in->fallback && !in->splits && !in->substeps;
}

/* Steps of the whole integration; ord[k] = 1 if step k is ordinary. */
static int dry_run(const step_case *c, const setup *S, unsigned char *ord) {
  fesd_integrator *it = create(c, S);
  if (!it) return 1;
  int st = 0;
  for (int k = 0; k < c->nsim && !st; k++) {
    fesd_step_info in;
    st = fesd_step(it, S->u, S->h, &in);
    ord[k] = !st && ordinary(it, &in);
  }
  fesd_free(&it);
  return st;
}

static int steps_mode(const step_case *c, int K) {
  setup S;
  unsigned char ord[MAX_STEPS];
  if (make(c, &S) || c->nsim > MAX_STEPS || dry_run(c, &S, ord)) return 1;
  int k0 = -1;
  for (int k = 2; k + K <= c->nsim && k0 < 0; k++) {
    int ok = 1;
    for (int j = 0; j < K; j++) ok &= ord[k + j];
    if (ok) k0 = k;
  }
  if (k0 < 0) {
    fprintf(stderr, "%s: no %d consecutive ordinary steps\n", c->name, K);
    return 1;
  }
  fesd_integrator *it = create(c, &S);
  int st = it ? 0 : 1, iters = 0;
  for (int k = 0; k < k0 + K && !st; k++) {
    fesd_step_info in;
    if (k == k0) CALLGRIND_TOGGLE_COLLECT;
    st = fesd_step(it, S.u, S.h, &in);
    if (k >= k0) iters += in.newton_iter;
  }
  CALLGRIND_TOGGLE_COLLECT;
  printf("%s window %d..%d newton_iter %d status %d\n", c->name, k0, k0 + K - 1, iters, st);
  fesd_free(&it);
  unmake(&S);
  return st != 0;
}

typedef struct {
  const step_case *c;
  const setup *S;
  int steps;
} cpu_job;

/* full cost of an integration, setup included (create, set_state, steps, free) */
static int cpu_fn(void *ctx) {
  cpu_job *j = ctx;
  fesd_integrator *it = create(j->c, j->S);
  int st = it ? 0 : 1;
  for (int k = 0; k < j->c->nsim && !st; k++) st = fesd_step(it, j->S->u, j->S->h, NULL);
  fesd_free(&it);
  return st;
}

static int cpu_mode(void) {
  FILE *csv = bench_csv("step_cpu.csv", "case,problem,s,nsim,us_per_integration,us_per_step");
  if (!csv) return 1;
  for (int i = 0; i < N_CASES; i++) {
    setup S;
    if (make(&cases[i], &S)) return 1;
    cpu_job j = {&cases[i], &S, cases[i].nsim};
    double t = bench_time(cpu_fn, &j);
    fprintf(csv, "%s,%s,%d,%d,%.2f,%.3f\n", cases[i].name, cases[i].prob, cases[i].s, cases[i].nsim, 1e6 * t,
            1e6 * t / cases[i].nsim);
    printf("%-16s %8.1f us per integration (%d steps)\n", cases[i].name, 1e6 * t, cases[i].nsim);
    fflush(stdout);
    unmake(&S);
  }
  fclose(csv);
  return 0;
}

/* Fixed costs: fesd_create and each step (e.g. the first switch step) as callgrind dumps. */
static int phases_run(const step_case *c, const setup *S, int run) {
  const int nsim = c->nsim;
  char name[96];
  snprintf(name, sizeof name, "run %d create", run);
  CALLGRIND_TOGGLE_COLLECT;
  fesd_integrator *it = create(c, S);
  CALLGRIND_DUMP_STATS_AT(name);
  int st = it ? 0 : 1;
  for (int k = 0; k < nsim && !st; k++) {
    fesd_step_info in;
    st = fesd_step(it, S->u, S->h, &in);
    CALLGRIND_TOGGLE_COLLECT; /* the label is no part of the step */
    snprintf(name, sizeof name, "run %d step %d %s newton %d factor %d solves %d", run, k,
             st ? "failed" : in.switch_step ? "switch" : ordinary(it, &in) ? "ordinary" : "other", in.newton_iter,
             in.factorizations, in.solves);
    CALLGRIND_TOGGLE_COLLECT;
    CALLGRIND_DUMP_STATS_AT(name);
  }
  CALLGRIND_TOGGLE_COLLECT;
  snprintf(name, sizeof name, "run %d free", run);
  CALLGRIND_TOGGLE_COLLECT;
  fesd_free(&it);
  CALLGRIND_DUMP_STATS_AT(name);
  CALLGRIND_TOGGLE_COLLECT;
  return st;
}

/* Two identical integrations: the first pays the process's one-time costs (lazy symbol
 * binding, heap growth, memoized tableaus), the second is what repeated use costs. */
static int phases_mode(const char *prob, int s, int nsim) {
  step_case c = {"phases", prob, s, nsim};
  setup S;
  if (make(&c, &S)) return 1;
  int st = phases_run(&c, &S, 1);
  if (!st) st = phases_run(&c, &S, 2);
  unmake(&S);
  return st != 0;
}

static int states_mode(void) {
  for (int i = 0; i < N_CASES; i++) {
    setup S;
    if (make(&cases[i], &S)) return 1;
    fesd_integrator *it = create(&cases[i], &S);
    int st = it ? 0 : 1, iters = 0;
    for (int k = 0; k < cases[i].nsim && !st; k++) {
      fesd_step_info in;
      st = fesd_step(it, S.u, S.h, &in);
      iters += in.newton_iter;
    }
    double x[64];
    fesd_get_state(it, NULL, x);
    printf("%s status %d newton %d x", cases[i].name, st, iters);
    for (int r = 0; r < S.model->nx && r < 64; r++) printf(" %a", x[r]);
    printf("\n");
    fesd_free(&it);
    unmake(&S);
  }
  return 0;
}

int main(int argc, char **argv) {
  if (argc == 2 && !strcmp(argv[1], "states")) return states_mode();
  if (argc >= 2 && !strcmp(argv[1], "list")) {
    for (int i = 0; i < N_CASES; i++) printf("%s\n", cases[i].name);
    return 0;
  }
  if (argc == 4 && !strcmp(argv[1], "steps")) {
    for (int i = 0; i < N_CASES; i++)
      if (!strcmp(argv[2], cases[i].name)) return steps_mode(&cases[i], atoi(argv[3]));
    fprintf(stderr, "unknown case %s\n", argv[2]);
    return 1;
  }
  if (argc == 5 && !strcmp(argv[1], "phases")) return phases_mode(argv[2], atoi(argv[3]), atoi(argv[4]));
  if (argc >= 2 && !strcmp(argv[1], "cpu")) {
    if (bench_init(argc - 1, argv + 1, "bench_step_cost cpu [--quick] [OUTDIR]")) return 1;
    return cpu_mode();
  }
  fprintf(stderr, "usage: bench_step_cost list | steps CASE K | phases PROB S NSIM | states | cpu [--quick] [OUTDIR]\n");
  return 1;
}
