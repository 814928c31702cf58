/* A failure says why, and flags say what an accepted result is worth.
 *  - x' = x^2 from x = 1 blows up at t = 1: a step over [0, 1.5] fails; the step info names
 *    the failing path, the residual reached, the shortest sub-step tried (T / 2^max_splits),
 *    the failing sub-step's start and the last accepted time; the state is unchanged; the
 *    failed step's Newton iterations are counted in the statistics (failed_steps too);
 *  - a sliding exit with Gauss-Legendre (no pinned exit) is flagged FESD_FLAG_EXIT_NOT_PINNED,
 *    the same exit with Radau IIA is not;
 *  - sensitivities of ordinary and switch steps are not flagged FESD_FLAG_SENS_INACCURATE;
 *  - too coarse steps are flagged FESD_FLAG_COARSE: the oscillator with 8 steps over [0, pi/2]
 *    (error 0.4 against the closed form) is, with 64 (error 1e-5) it is not. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "fesd.h"
#include "problems/problems.h"
#include "../check.h"

static int sq_field(int sys, int mode, double t, const double *x, const double *u, double *f, void *user) {
  f[0] = mode == 0 ? x[0] * x[0] : x[0] * x[0]; /* the same smooth field in both regions */
  return 0;
}
static int sq_sw(int sys, double t, const double *x, const double *u, double *c, void *user) {
  c[0] = x[0] + 10; /* never reached */
  return 0;
}

int main(void) {
  int fails = 0;
  {
    const int nm[1] = {2}, ns[1] = {1};
    fesd_model m = {.nx = 1, .nsys = 1, .n_modes = nm, .n_switch = ns, .field = sq_field, .sw = sq_sw};
    fesd_settings set;
    fesd_settings_default(&set);
    set.max_splits = 3;
    fesd_integrator *it;
    fesd_create(&it, &m, &set);
    const double x0 = 1;
    fesd_set_state(it, 0, &x0, NULL);
    fesd_step_info info;
    int st = fesd_step(it, NULL, 1.5, &info);
    double t, x;
    fesd_get_state(it, &t, &x);
    fesd_stats S;
    fesd_get_stats(it, &S);
    FESD_TEST_CHECK(st == FESD_ERR_STEP_FAILED, "blow-up step: %s", fesd_status_name(st));
    FESD_TEST_CHECK(t == 0 && x == 1, "state changed by a failed step: t %g x %g", t, x);
    FESD_TEST_CHECK(info.failed_path && info.failed_residual > set.newton_tol,
                    "failed path %s, residual %.2e", info.failed_path ? info.failed_path : "(none)",
                    info.failed_residual);
    FESD_TEST_CHECK(fabs(info.min_substep - 1.5 / 8) < 1e-15, "shortest sub-step %g (expected %g)", info.min_substep,
                    1.5 / 8);
    FESD_TEST_CHECK(info.failed_time < 1.0 && info.failed_time >= info.last_time && info.last_time <= 1.0,
                    "failed sub-step at %g, last accepted %g (the blow-up is at 1)", info.failed_time,
                    info.last_time);
    FESD_TEST_CHECK(S.failed_steps == 1 && S.steps == 0 && S.newton_iter == info.newton_iter && info.newton_iter > 0,
                    "stats of the failed step: failed %d, steps %d, iterations %d (step info %d)", S.failed_steps,
                    S.steps, S.newton_iter, info.newton_iter);
    printf("blow-up: %s, path '%s', residual %.1e, shortest sub-step %g, failed at t = %.4f, last accepted %.4f, "
           "%d iterations counted\n", fesd_status_name(st), info.failed_path, info.failed_residual, info.min_substep,
           info.failed_time, info.last_time, S.newton_iter);
    fesd_free(&it);
  }
  {
    fesd_problem P;
    fesd_problem_get("sign-c", &P);
    const fesd_rk_family fam[2] = {FESD_RK_GAUSS_LEGENDRE, FESD_RK_RADAU_IIA};
    for (int f = 0; f < 2; f++) {
      fesd_settings set;
      fesd_settings_default(&set);
      set.family = fam[f];
      fesd_integrator *it;
      fesd_create(&it, &P.model, &set);
      fesd_set_state(it, 0, P.x0, NULL);
      int st = 0;
      for (int k = 0; k < 21 && !st; k++) st = fesd_step(it, NULL, 0.1, NULL);
      fesd_stats S;
      fesd_get_stats(it, &S);
      const int expect = fam[f] == FESD_RK_GAUSS_LEGENDRE;
      FESD_TEST_CHECK(st == FESD_OK && (S.exit_not_pinned_steps > 0) == expect, "sign-c %s: %s, %d flagged exits",
                      fesd_rk_family_name(fam[f]), fesd_status_name(st), S.exit_not_pinned_steps);
      printf("sign-c %-6s: exit flagged not pinned in %d step(s)\n", fesd_rk_family_name(fam[f]),
             S.exit_not_pinned_steps);
      fesd_free(&it);
    }
  }
  {
    const char *probs[3] = {"oscillator", "sign-a", "ocp-dynamics"};
    for (int p = 0; p < 3; p++) {
      fesd_problem P;
      fesd_problem_get(probs[p], &P);
      fesd_settings set;
      fesd_settings_default(&set);
      set.sensitivities = 1;
      fesd_integrator *it;
      fesd_create(&it, &P.model, &set);
      fesd_set_state(it, 0, P.x0, P.u);
      int st = 0;
      for (int k = 0; k < 20 && !st; k++) st = fesd_step(it, P.u, P.T / 20, NULL);
      fesd_stats S;
      fesd_get_stats(it, &S);
      FESD_TEST_CHECK(st == FESD_OK && S.sens_inaccurate_steps == 0, "%s: %s, %d steps with doubtful sensitivities",
                      probs[p], fesd_status_name(st), S.sens_inaccurate_steps);
      fesd_free(&it);
    }
    printf("sensitivities of the oscillator, sign-a, ocp-dynamics: none flagged\n");
  }
  {
    fesd_problem P;
    fesd_problem_get("oscillator", &P);
    for (int nsim = 8; nsim <= 64; nsim *= 8) {
      fesd_settings set;
      fesd_settings_default(&set);
      fesd_integrator *it;
      fesd_create(&it, &P.model, &set);
      fesd_set_state(it, 0, P.x0, NULL);
      int st = 0;
      for (int k = 0; k < nsim && !st; k++) st = fesd_step(it, NULL, P.T / nsim, NULL);
      fesd_stats S;
      fesd_get_stats(it, &S);
      double x[2], xe[2];
      fesd_get_state(it, NULL, x);
      P.exact(P.T, xe);
      const double err = fmax(fabs(x[0] - xe[0]), fabs(x[1] - xe[1]));
      FESD_TEST_CHECK(st == FESD_OK && (S.coarse_steps > 0) == (nsim == 8), "oscillator N_sim = %d: error %.1e, %d coarse steps",
                      nsim, err, S.coarse_steps);
      printf("oscillator, N_sim = %2d: error %.1e, %d steps flagged coarse\n", nsim, err, S.coarse_steps);
      fesd_free(&it);
    }
  }
  printf("%d failures\n", fails);
  return fails != 0;
}
