/* Sliding exits, pinned exit rows (exit_rows = 1, docs/sliding_exit.md) against the paper's
 * formulation (exit_rows = 0) and the standard method, side by side: state error at T and
 * exit-time error vs N_sim, Radau IIA s = 2, 3.
 *   sign-c         x' in -sign(x) + t, T = 2.1: slides until t = 1, then x = (t-1)^2 / 2
 *   slide-exit-2d  curved surface, exit at t* = 1.02617735 (reference by bisection and
 *                  Simpson); as in tests/fesd/test_sliding_exit.c the step is chosen per N
 *                  so that the exit sits at 0.4 of its step (no lucky alignment)
 * Exit time: the event nearest t* (NaN when the method reports none).
 * Output: sliding_exit.csv, sliding_exit_orders.csv (fitted orders, points above 3e-13: the round-off floor of ~300 steps). */
#include <math.h>
#include <string.h>

#include "bench_util.h"

#define MAXG 16

int main(int argc, char **argv) {
  if (bench_init(argc, argv, "sliding exits: exit_rows = 1 vs 0 vs standard")) return 1;
  static const int full_n[] = {10, 14, 20, 28, 40, 57, 80, 113, 160, 226, 320}, quick_n[] = {10, 40};
  const int *grid = bench_opt.quick ? quick_n : full_n, ng = bench_opt.quick ? 2 : 11;
  FILE *csv = bench_csv("sliding_exit.csv",
                        "problem,variant,s,nsim,h,err_state,err_exit,newton_iter,fallback_steps,status");
  FILE *ord = bench_csv("sliding_exit_orders.csv", "problem,variant,s,order_state,order_exit,max_err_state,"
                                                   "max_err_exit");
  if (!csv || !ord) return 1;
  static const struct {
    const char *name;
    fesd_method method;
    int exit_rows;
  } var[] = {{"fesd", FESD_METHOD_FESD, 1}, {"fesd-exit0", FESD_METHOD_FESD, 0}, {"standard", FESD_METHOD_STANDARD, 1}};
  const char *probs[] = {"sign-c", "slide-exit-2d"};
  printf("%-13s %-10s s | state: order  max err | exit time: order  max err\n", "problem", "variant");
  for (int p = 0; p < 2; p++) {
    fesd_problem P;
    fesd_problem_get(probs[p], &P);
    double t_exit = 1.0, x2;
    if (p == 1) fesd_problem_slide_exit_point(&t_exit, &x2);
    for (int v = 0; v < 3; v++)
      for (int s = 2; s <= 3; s++) {
        fesd_settings set;
        fesd_settings_default(&set);
        set.method = var[v].method;
        set.exit_rows = var[v].exit_rows;
        set.stages = s;
        fesd_integrator *it = bench_create(&P, &set);
        if (!it) return 1;
        double h[MAXG], ex[MAXG], et[MAXG], mx = 0, mt = 0;
        for (int g = 0; g < ng; g++) {
          double H = P.T / grid[g];
          if (p == 1) H = t_exit / (floor(t_exit / H) + 0.4);
          bench_job j = {it, &P, grid[g], grid[g] * H};
          bench_run r;
          int st = bench_integrate(&j, &r);
          h[g] = H;
          ex[g] = st ? NAN : r.err;
          et[g] = st ? NAN : fabs(bench_event_near(&r, t_exit, -1) - t_exit);
          mx = fmax(mx, ex[g]), mt = fmax(mt, et[g]);
          fprintf(csv, "%s,%s,%d,%d,%.6e,%.6e,%.6e,%d,%d,%d\n", P.name, var[v].name, s, grid[g], H, ex[g], et[g],
                  r.stats.newton_iter, r.stats.fallback_steps, st);
        }
        fesd_free(&it);
        double px = bench_slope(h, ex, ng, 3e-13, 1.0, NULL), pt = bench_slope(h, et, ng, 3e-13, 1.0, NULL);
        fprintf(ord, "%s,%s,%d,%.3f,%.3f,%.3e,%.3e\n", P.name, var[v].name, s, px, pt, mx, mt);
        printf("%-13s %-10s %d |   %6.2f  %.1e |       %6.2f  %.1e\n", P.name, var[v].name, s, px, mx, pt, mt);
      }
  }
  fclose(csv);
  fclose(ord);
  return 0;
}
