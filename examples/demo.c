/* The main demo: integrate the paper's examples with FESD and with standard
 * time-stepping (same Runge-Kutta method, same N_FE and number of steps) and print
 * the accuracy and the CPU time side by side. */
#include <math.h>
#include <stdio.h>
#include <string.h>
#include <time.h>

#include "fesd.h"
#include "problems/problems.h"

static double cpu_now(void) {
  struct timespec ts;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

typedef struct {
  int ok;
  double err, t_switch, cpu_ms;
  int steps, iters, events;
} run_result;

/* One integration: the error (max over the step ends against the exact solution), the first
 * switch time, and the CPU time (median-free: mean over repeats of at least 50 ms). */
static int run(const fesd_problem *P, fesd_settings *set, int nsim, run_result *r) {
  fesd_integrator *it;
  memset(r, 0, sizeof(*r));
  r->t_switch = NAN;
  if (fesd_create(&it, &P->model, set) != FESD_OK) return 1;
  int reps = 0;
  double t0 = cpu_now(), el = 0;
  double x[FESD_PROBLEM_MAX_NX];
  do { /* repeat until 50 ms of CPU so short runs are timed reliably */
    fesd_set_state(it, 0.0, P->x0, P->u);
    r->t_switch = NAN;
    r->err = 0;
    for (int k = 0; k < nsim; k++) {
      if (fesd_step(it, P->u, P->T / nsim, NULL) != FESD_OK) {
        fesd_free(&it);
        return 1;
      }
      double t, xe[FESD_PROBLEM_MAX_NX];
      fesd_get_state(it, &t, x);
      P->exact(t, xe);
      for (int i = 0; i < P->model.nx; i++) r->err = fmax(r->err, fabs(x[i] - xe[i]));
      const fesd_event *ev;
      int ne;
      fesd_last_events(it, &ev, &ne);
      if (ne > 0 && isnan(r->t_switch)) r->t_switch = ev[0].t;
    }
    reps++;
    el = cpu_now() - t0;
  } while (el < 0.05);
  r->cpu_ms = 1e3 * el / reps;
  fesd_stats st;
  fesd_get_stats(it, &st);
  r->steps = st.steps;
  r->iters = st.newton_iter;
  r->events = st.events;
  r->ok = 1;
  fesd_free(&it);
  return 0;
}

int main(void) {
  struct {
    const char *name;
    int stages, nsim;
  } cases[] = {{"oscillator", 3, 40}, {"oscillator", 4, 20}, {"sign-a", 2, 20}, {"sign-b", 2, 20},
               {"sign-c", 2, 20},     {"sign-c", 3, 40},     {"ocp-dynamics", 2, 40}};
  printf("libfesd demo: FESD vs standard time-stepping (Radau IIA, N_FE = 2 elements per step)\n");
  printf("error = max over the step ends of |x(t_k) - exact|_inf; t_switch = first detected event;\n"
         "CPU ms = one integration over [0, T] (thread CPU time)\n\n");
  printf("%-13s %2s %5s | %-10s %-10s %8s %6s | %-10s %-10s %8s %6s | %s\n", "problem", "s", "N_sim",
         "FESD err", "t_switch", "CPU ms", "iters", "std err", "t_switch", "CPU ms", "iters",
         "err ratio");
  int fails = 0;
  for (size_t c = 0; c < sizeof(cases) / sizeof(cases[0]); c++) {
    fesd_problem P;
    fesd_problem_get(cases[c].name, &P);
    fesd_settings set;
    fesd_settings_default(&set);
    set.stages = cases[c].stages;
    run_result rf, rs;
    fails += run(&P, &set, cases[c].nsim, &rf);
    set.method = FESD_METHOD_STANDARD;
    fails += run(&P, &set, cases[c].nsim, &rs);
    printf("%-13s %2d %5d | %-10.2e %-10.6f %8.3f %6d | %-10.2e %-10.6f %8.3f %6d | %.1e\n",
           cases[c].name, cases[c].stages, cases[c].nsim, rf.err, rf.t_switch, rf.cpu_ms, rf.iters,
           rs.err, rs.t_switch, rs.cpu_ms, rs.iters, rs.err / fmax(rf.err, 1e-300));
  }
  printf("\nexact first switch times: oscillator 1 (crossing), sign-a 1/3 (crossing), sign-b 1 "
         "(entering sliding),\nsign-c 1 (leaving sliding), ocp-dynamics %.6f (entering sliding on c2 = 0; "
         "co-dimension 2 at 2pi/3)\n", fesd_problem_ocp_t1());
  if (fails) printf("%d runs FAILED\n", fails);
  return fails != 0;
}
