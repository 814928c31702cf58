/* Stewart-Anitescu (paper Sec. 4.5, Fig. ivp_problem): V(x0) and dV/dx0 from FESD (with
 * its sensitivities) match the exact formulas to 1e-8 over x0 in [-3, 0.5] away from
 * x0 = 0, for Gauss-Legendre s = 2 with N_FE = 25 (one step, as in the paper) and Radau
 * IIA s = 3; a secant shooting on dV/dx0 from 20 starts converges to
 * x0* = (9 - sqrt(417))/8 to 1e-8. */
#include <math.h>
#include <stdio.h>

#include "fesd.h"
#include "problems/problems.h"

int main(void) {
  int fails = 0;
  fesd_problem P;
  fesd_problem_get("stewart-anitescu", &P);
  const double xstar = (9 - sqrt(417.0)) / 8;
  struct {
    fesd_rk_family fam;
    int s, nfe, nsim;
  } cases[] = {{FESD_RK_GAUSS_LEGENDRE, 2, 25, 1}, {FESD_RK_RADAU_IIA, 3, 2, 20}};
  for (int c = 0; c < 2; c++) {
    fesd_settings set;
    fesd_settings_default(&set);
    set.family = cases[c].fam;
    set.stages = cases[c].s;
    set.n_fe = cases[c].nfe;
    set.sensitivities = 1;
    fesd_integrator *it;
    if (fesd_create(&it, &P.model, &set)) return 1;
    double ev = 0, eg = 0;
    int bad = 0;
    for (int i = 0; i <= 70; i++) {
      double x0 = -3 + 3.5 * i / 70, V, dV, dVe;
      if (fabs(x0) < 1e-3) continue;
      if (fesd_sa_value(it, x0, cases[c].nsim, &V, &dV)) {
        bad++;
        continue;
      }
      double Ve = fesd_sa_exact_value(x0, &dVe);
      ev = fmax(ev, fabs(V - Ve));
      eg = fmax(eg, fabs(dV - dVe));
    }
    double worst = 0;
    int maxit = 0, sbad = 0;
    for (int k = 0; k < 20; k++) {
      double x0 = -3 + 3.5 * k / 19, xo;
      int iters;
      if (fesd_sa_shoot(it, x0, cases[c].nsim, &xo, &iters)) sbad++;
      worst = fmax(worst, fabs(xo - xstar));
      if (iters > maxit) maxit = iters;
    }
    int ok = !bad && !sbad && ev <= 1e-8 && eg <= 1e-8 && worst <= 1e-8;
    fails += !ok;
    printf("%-6s s=%d N_FE=%2d N_sim=%2d: max |V - exact| %.1e, max |dV/dx0 - exact| %.1e; shooting "
           "from 20 starts: max |x0 - x0*| %.1e (<= %d secant steps) %s\n",
           fesd_rk_family_name(set.family), set.stages, set.n_fe, cases[c].nsim, ev, eg, worst,
           maxit, ok ? "ok" : "FAIL");
    fesd_free(&it);
  }
  printf("%d failures\n", fails);
  return fails != 0;
}
