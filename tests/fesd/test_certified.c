/* The certified start solve (step.c: a stage-Newton guess with one active mode per subsystem
 * is checked on its V rows, not by the solver's residual of the whole step system) against the
 * full check: every problem of src/problems, every implicit family and the explicit one, both
 * methods, with and without sensitivities, over the problems' horizons (crossings, sliding
 * modes, exits, codimension 2). The two runs must agree bit for bit (states, sensitivities,
 * events, Newton iterations): a step the shortcut certifies is one the full check passes with
 * no iteration. Counts printed; more than 1000 certified start solves are required, and none
 * when newton_tol is below the round-off of the rows that hold by construction. */
#include <stdio.h>
#include <string.h>

#include "../check.h"
#include "fesd/integrator.h"
#include "problems/problems.h"

typedef struct {
  double x[FESD_PROBLEM_MAX_NX], Sx[FESD_PROBLEM_MAX_NX * FESD_PROBLEM_MAX_NX];
  double Su[FESD_PROBLEM_MAX_NX * FESD_PROBLEM_MAX_NU];
  double ev_t[4096];
  int n_ev, st, newton;
  long certified;
} run_out;

static void run(const fesd_problem *P, const fesd_settings *set, int nsim, int full, run_out *o) {
  memset(o, 0, sizeof *o);
  fesd_integrator *it = NULL;
  o->st = fesd_create(&it, &P->model, set);
  if (o->st) return;
  it->full_check = full;
  o->st = fesd_set_state(it, 0.0, P->x0, P->u);
  for (int k = 0; k < nsim && !o->st; k++) {
    fesd_step_info info;
    o->st = fesd_step(it, P->u, P->T / nsim, &info);
    const fesd_event *ev;
    int n;
    if (!o->st && !fesd_last_events(it, &ev, &n))
      for (int e = 0; e < n && o->n_ev < 4096; e++) o->ev_t[o->n_ev++] = ev[e].t;
  }
  double t;
  fesd_get_state(it, &t, o->x);
  if (set->sensitivities) fesd_get_sensitivities(it, o->Sx, P->model.nu ? o->Su : NULL);
  fesd_stats stats;
  fesd_get_stats(it, &stats);
  o->newton = stats.newton_iter;
  o->certified = it->n_certified;
  fesd_free(&it);
}

int main(void) {
  int fails = 0, runs = 0;
  long cert = 0;
  const struct {
    fesd_rk_family fam;
    int s;
  } tabs[] = {{FESD_RK_RADAU_IIA, 1}, {FESD_RK_RADAU_IIA, 2}, {FESD_RK_RADAU_IIA, 3}, {FESD_RK_RADAU_IIA, 5},
              {FESD_RK_GAUSS_LEGENDRE, 1}, {FESD_RK_GAUSS_LEGENDRE, 2}, {FESD_RK_GAUSS_LEGENDRE, 3},
              {FESD_RK_LOBATTO_IIIA, 3}, {FESD_RK_LOBATTO_IIIC, 2}, {FESD_RK_LOBATTO_IIIC, 3},
              {FESD_RK_EXPLICIT, 4}};
  const int n_tabs = (int)(sizeof tabs / sizeof tabs[0]);
  const char *const *names = fesd_problem_names();
  for (int q = 0; names[q]; q++) {
    fesd_problem P;
    if (fesd_problem_get(names[q], &P)) continue;
    const int nx = P.model.nx, nu = P.model.nu;
    for (int b = 0; b < n_tabs; b++)
      for (int meth = 0; meth < 2; meth++)
        for (int sens = 0; sens < 2; sens++) {
          fesd_settings set;
          fesd_settings_default(&set);
          set.family = tabs[b].fam;
          set.stages = tabs[b].s;
          set.method = meth ? FESD_METHOD_STANDARD : FESD_METHOD_FESD;
          set.sensitivities = sens;
          const int nsim = 30;
          static run_out a, f;
          run(&P, &set, nsim, 0, &a);
          run(&P, &set, nsim, 1, &f);
          runs++;
          cert += a.certified;
          FESD_TEST_CHECK(f.certified == 0, "%s: full check certified %ld steps", names[q], f.certified);
          int same = a.st == f.st && a.n_ev == f.n_ev && a.newton == f.newton &&
                     !memcmp(a.x, f.x, (size_t)nx * sizeof(double)) &&
                     !memcmp(a.ev_t, f.ev_t, (size_t)a.n_ev * sizeof(double));
          if (sens)
            same = same && !memcmp(a.Sx, f.Sx, (size_t)nx * nx * sizeof(double)) &&
                   !memcmp(a.Su, f.Su, (size_t)nx * nu * sizeof(double));
          FESD_TEST_CHECK(same,
                          "%s family %d s = %d method %d sens %d: status %d / %d, events %d / %d, "
                          "newton %d / %d, x0 %.17g / %.17g",
                          names[q], (int)tabs[b].fam, tabs[b].s, meth, sens, a.st, f.st, a.n_ev, f.n_ev,
                          a.newton, f.newton, a.x[0], f.x[0]);
        }
  }
  /* below the construction's round-off (64 (N + s) eps) newton_tol is left to the solver */
  {
    fesd_problem P;
    fesd_problem_get("oscillator", &P);
    fesd_settings set;
    fesd_settings_default(&set);
    set.newton_tol = 1e-14;
    static run_out o;
    run(&P, &set, 30, 0, &o);
    printf("newton_tol 1e-14: %ld certified start solves (expected 0), status %d\n", o.certified, o.st);
    FESD_TEST_CHECK(o.certified == 0, "newton_tol 1e-14: %ld start solves certified", o.certified);
  }
  printf("%d run pairs, %ld certified start solves, identical results in all: %s\n", runs, cert,
         fails ? "no" : "yes");
  FESD_TEST_CHECK(cert > 1000, "only %ld certified start solves: the shortcut is not exercised", cert);
  return fails != 0;
}
