/* No heap allocation inside the step / Newton loop: malloc, calloc and realloc are
 * interposed by this program and counted while fesd_set_state and fesd_step run (after
 * fesd_create, where everything is allocated).
 *  - dense backend: full integrations with crossings, sliding entry and exit: 0 allocations;
 *  - KLU (chosen; AUTO takes it above n = 50 without a border): ordinary steps with an unchanged row pattern
 *    allocate nothing; a step that brings a row pattern the solver has not seen (a switch
 *    step, and the first step after it) analyses it, which allocates by design (docs/ncp.md);
 *    the analyses are cached, so a second integration on the same integrator allocates nothing;
 *  - AUTO: bordered step systems up to 2 dense_max_n unknowns use a dense LU (ls_bdense.c):
 *    a second integration allocates nothing either.
 * Skipped (exit 77) under AddressSanitizer, which owns malloc itself. */
#include <stdio.h>
#include <stdlib.h>

#include "fesd.h"
#include "problems/problems.h"

#include "../alloc_hook.h"

#if !ALLOC_HOOK_ACTIVE
int main(void) {
  printf("skipped under AddressSanitizer\n");
  return 77;
}
#else
/* allocations during set_state + nsim steps (of the last of `passes` integrations on one
 * integrator); per-step counts in per_step (may be NULL) */
static long count_run(const char *name, fesd_ncp_backend bk, int s, int nsim, int passes, long *per_step) {
  fesd_problem P;
  fesd_problem_get(name, &P);
  fesd_settings set;
  fesd_settings_default(&set);
  set.stages = s;
  set.ncp.backend = bk;
  fesd_integrator *it;
  if (fesd_create(&it, &P.model, &set)) return -1;
  long c0 = 0;
  int st = 0;
  for (int pass = 0; pass < passes && !st; pass++) {
    c0 = g_count;
    st = fesd_set_state(it, 0, P.x0, P.u);
    for (int k = 0; k < nsim && !st; k++) {
      long before = g_count;
      st = fesd_step(it, P.u, P.T / nsim, NULL);
      if (per_step) per_step[k] = g_count - before;
    }
  }
  long total = g_count - c0;
  fesd_free(&it);
  return st ? -1 : total;
}

int main(void) {
  int fails = 0;
  const char *probs[] = {"oscillator", "sign-b", "sign-c", "ocp-dynamics", "slide-exit-2d"};
  for (int p = 0; p < 5; p++) {
    long a = count_run(probs[p], FESD_NCP_BACKEND_DENSE, 3, 20, 1, NULL);
    int ok = a == 0;
    fails += !ok;
    printf("%-14s dense backend, Radau s=3, 20 steps: %ld allocations %s\n", probs[p], a, ok ? "ok" : "FAIL");
  }
  /* KLU: Radau s = 5 on the oscillator (n = 76) */
  long per[20];
  long a = count_run("oscillator", FESD_NCP_BACKEND_KLU, 5, 20, 1, per);
  int changes = 0; /* steps 0, 1: first analysis and first refactorization */
  for (int k = 2; k < 20; k++) changes += per[k] > 0;
  int ok = a >= 0 && changes <= 2; /* the switch step and the step after it (pattern changes) */
  fails += !ok;
  printf("oscillator     KLU backend, Radau s=5, 20 steps: %ld allocations in %d of steps 2..19 "
         "(row-pattern changes at the switch) %s\n", a, changes, ok ? "ok" : "FAIL");
  /* second integration, KLU: every pattern is in the solver's cache; AUTO: the step systems of
   * Radau s = 5 with a border (n <= 2 dense_max_n) take the bordered dense LU, whose arrays are
   * made with the first selection */
  const fesd_ncp_backend second[] = {FESD_NCP_BACKEND_KLU, FESD_NCP_BACKEND_AUTO};
  for (int b = 0; b < 2; b++)
    for (int p = 0; p < 5; p++) {
      a = count_run(probs[p], second[b], 5, 20, 2, NULL);
      ok = a == 0;
      fails += !ok;
      printf("%-14s %s backend, Radau s=5, 20 steps, second integration: %ld allocations %s\n", probs[p],
             fesd_ncp_backend_name(second[b]), a, ok ? "ok" : "FAIL");
    }
  printf("%d failures\n", fails);
  return fails != 0;
}
#endif
