/* One run of the stick-slip friction chain (the runs of chain_pareto.csv in bench_growth) for
 * profiling: CPU time, steps, events, Newton iterations, factorizations and the final state
 * (checksum, and every entry in %a with --states, so that a change of the results shows).
 *   bench_chain_run N S H T [fesd|standard] [--states]
 * Under callgrind: valgrind --tool=callgrind build/bench/bench_chain_run 64 2 0.1 4 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bench_util.h"
#include "problems/friction_chain.h"

int main(int argc, char **argv) {
  if (argc < 5) {
    fprintf(stderr, "usage: %s N S H T [fesd|standard] [--states]\n", argv[0]);
    return 2;
  }
  const int n = atoi(argv[1]), s = atoi(argv[2]);
  const double h = atof(argv[3]), T = atof(argv[4]);
  const int standard = argc > 5 && !strcmp(argv[5], "standard");
  const int states = argc > 6 && !strcmp(argv[6], "--states");
  fesd_friction_chain fc;
  if (n < 1 || s < 1 || !(h > 0) || !(T > 0) || fesd_friction_chain_stick_slip(&fc, n)) return 2;
  fesd_settings set;
  fesd_settings_default(&set);
  set.stages = s;
  if (standard) set.method = FESD_METHOD_STANDARD;
  fesd_integrator *it;
  int st = fesd_create(&it, &fc.model, &set);
  if (st) return 1;
  const int nsteps = (int)lround(T / h);
  const double c0 = bench_cpu();
  st = fesd_set_state(it, 0, fc.x0, NULL);
  for (int k = 0; k < nsteps && !st; k++) st = fesd_step(it, NULL, h, NULL);
  const double cpu = bench_cpu() - c0;
  fesd_stats S;
  fesd_get_stats(it, &S);
  double *x = malloc(2 * (size_t)n * sizeof *x), sum = 0;
  if (!x) return 1;
  fesd_get_state(it, NULL, x);
  for (int i = 0; i < 2 * n; i++) sum += fabs(x[i]);
  printf("n %d s %d h %g T %g %s: status %d cpu %.2f ms steps %d events %d newton %d factorizations %d "
         "solves %d substeps %d sum|x| %.15e\n",
         n, s, h, T, standard ? "standard" : "fesd", st, 1e3 * cpu, S.steps, S.events, S.newton_iter,
         S.factorizations, S.solves, S.substeps, sum);
  for (int i = 0; states && i < 2 * n; i++) printf("%a\n", x[i]);
  free(x);
  fesd_free(&it);
  fesd_friction_chain_free(&fc);
  return st != 0;
}
