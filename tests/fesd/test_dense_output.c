/* Dense output from the collocation polynomial: on the oscillator (exact solution known,
 * switch at t = 1) the error inside the elements converges at the stage order + 1 (s + 1)
 * for Radau IIA and Gauss-Legendre; methods without a collocation polynomial refuse. */
#include <math.h>
#include <stdio.h>

#include "fesd.h"
#include "problems/problems.h"

static double run(fesd_problem *P, fesd_rk_family fam, int s, int nsim, int *status) {
  fesd_settings set;
  fesd_settings_default(&set);
  set.family = fam;
  set.stages = s;
  fesd_integrator *it;
  *status = fesd_create(&it, &P->model, &set);
  if (*status) return INFINITY;
  fesd_set_state(it, 0, P->x0, NULL);
  double worst = 0;
  for (int k = 0; k < nsim && !*status; k++) {
    *status = fesd_step(it, NULL, P->T / nsim, NULL);
    fesd_step_data d;
    fesd_last_step_data(it, &d);
    for (int e = 0; e < d.n_elements; e++)
      for (int q = 1; q < 5; q++) {
        double t = d.t[e] + 0.2 * q * d.h[e], x[2], xe[2];
        *status |= fesd_dense_output(it, t, x);
        fesd_problem_oscillator_exact(t, xe);
        worst = fmax(worst, fmax(fabs(x[0] - xe[0]), fabs(x[1] - xe[1])));
      }
  }
  fesd_free(&it);
  return worst;
}

int main(void) {
  int fails = 0;
  fesd_problem P;
  fesd_problem_get("oscillator", &P);
  struct {
    fesd_rk_family fam;
    int s;
  } cases[] = {{FESD_RK_RADAU_IIA, 2}, {FESD_RK_RADAU_IIA, 3}, {FESD_RK_GAUSS_LEGENDRE, 2}};
  for (int c = 0; c < 3; c++) {
    const int grid[4] = {20, 40, 80, 160};
    double e[4];
    int st = 0;
    for (int g = 0; g < 4; g++) {
      int sg;
      e[g] = run(&P, cases[c].fam, cases[c].s, grid[g], &sg);
      st |= sg;
    }
    double order = log(e[0] / e[3]) / log(8.0);
    int ok = !st && order >= cases[c].s + 0.5;
    fails += !ok;
    printf("%s s=%d: dense output error %.1e %.1e %.1e %.1e, order %.2f (expected s+1 = %d) %s\n",
           fesd_rk_family_name(cases[c].fam), cases[c].s, e[0], e[1], e[2], e[3], order, cases[c].s + 1,
           ok ? "ok" : "FAIL");
  }
  /* no collocation polynomial: a clear refusal */
  fesd_settings set;
  fesd_settings_default(&set);
  set.family = FESD_RK_EXPLICIT;
  set.stages = 4;
  fesd_integrator *it;
  fesd_create(&it, &P.model, &set);
  fesd_set_state(it, 0, P.x0, NULL);
  double x[2];
  int st0 = fesd_dense_output(it, 0.0, x);
  fesd_step(it, NULL, 0.1, NULL);
  int st1 = fesd_dense_output(it, 0.05, x);
  fesd_free(&it);
  int ok = st0 != FESD_OK && st1 == FESD_ERR_INVALID_ARG;
  fails += !ok;
  printf("explicit RK: dense output refused (%s) %s\n", fesd_status_name(st1), ok ? "ok" : "FAIL");
  printf("%d failures\n", fails);
  return fails != 0;
}
