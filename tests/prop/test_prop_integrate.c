/* The error-controlled front (fesd_integrate_grid, the event log) on random piecewise-affine
 * systems, against the independent event-driven reference pwa_ref.c (property test).
 *
 * Systems of six kinds (pwa_random_system, T = 3, controls u through B): piecewise-constant
 * crossings, sliding, several subsystems sliding; affine crossings, sliding exits, several
 * subsystems sliding. Each is
 * integrated as a user would: tolerances rtol in {1e-4, 1e-6, 1e-8} (atol = 1e-3 rtol), a
 * random family (Radau IIA s = 2, 3, Lobatto IIIC s = 3, Gauss-Legendre s = 2 where no mode
 * leaves a sliding mode: it cannot pin exits), states at 4 random output times and at T.
 * A run is right when it returns FESD_OK with the reference's event log (subsystem and kind, in
 * order; times within 1e-3 T) and every output state within ERR_FACTOR (rtol |x| + atol) of
 * the reference (the global error of an integration whose local errors are held at the
 * tolerance; componentwise). Asserted: every run right, unless a step flagged it
 * (FESD_FLAG_COARSE, NONUNIQUE or EXIT_NOT_PINNED, which say the state is not to be trusted):
 * FESD_OK must mean right. And no run takes more than MAX_STEPS steps (an error estimate that
 * does not fall with h makes the controller collapse the step). Prints the counts, the worst
 * error / tolerance per rtol and the most steps.
 * --shard K N: every N-th system from the K-th (tests/prop/meson.build); -v (last): every run. */
#include <stdlib.h>

#include "prop_util.h"

#define T_END 3.0
#define N_OUT 5
#define N_PER_KIND 24
#define RUNS_PER_SYSTEM 3
/* global error / local tolerance: measured worst 4.3 (tests/fesd/test_integrate.c asserts 1.7
 * on five problems); 10 leaves room for the error growth of random fields */
#define ERR_FACTOR 10.0
/* accepted steps of a run: measured at most 2139 (Radau IIA s = 2, rtol 1e-8: its embedded
 * estimate is O(h^3)); an error estimate that does not shrink with h (before: the f_0 of a
 * co-dimension-2 sliding mode, fesd__stage_theta) collapses the step instead (210,000 steps,
 * the state right) */
#define MAX_STEPS 20000

static const pr_category KINDS[] = {
    /* name, affine, K, nx, nu, slide_prob, a_scale, rot, min_ev, entry, exit, multi */
    {"constant, crossings", 0, 1, 3, 2, 3, 1, 2, 0.0, 0, 0, 4, -1, -1, -1},
    {"constant, sliding", 0, 1, 3, 2, 3, 1, 2, 0.6, 0, 0, 3, 1, -1, -1},
    {"constant, several sliding", 0, 2, 3, 2, 3, 1, 2, 0.6, 0, 0, 3, 1, -1, 1},
    {"affine, crossings", 1, 1, 3, 2, 3, 1, 2, 0.0, 0.3, 2, 4, -1, -1, -1},
    {"affine, exits", 1, 1, 3, 2, 3, 1, 2, 0.6, 0.6, 3, 3, 1, 1, -1},
    {"affine, several sliding", 1, 2, 3, 2, 3, 1, 2, 0.6, 0.6, 3, 2, 1, 0, 1},
};
#define N_KINDS ((int)(sizeof(KINDS) / sizeof(KINDS[0])))

typedef struct {
  int runs, ok, right, flagged, wrong, failed, slow, max_steps;
  double worst[3]; /* error / tolerance per rtol */
} tally;

int main(int argc, char **argv) {
  int shard = 0, n_shards = 1, fails = 0;
  const int verbose = argc > 1 && !strcmp(argv[argc - 1], "-v");
  if (argc >= 4 && !strcmp(argv[1], "--shard")) shard = atoi(argv[2]), n_shards = atoi(argv[3]);
  if (n_shards < 1 || shard < 0 || shard >= n_shards) return 2;
  const double RTOL[3] = {1e-4, 1e-6, 1e-8};
  tally all = {0};
  pwa_rng pick = {90210}; /* run settings, the same in every shard */
  int index = 0;
  for (int c = 0; c < N_KINDS; c++) {
    pwa_rng rng = {424242 + pr_seed_off() + 100 * (uint64_t)c};
    tally tk = {0};
    for (int i = 0; i < N_PER_KIND; i++, index++) {
      /* every shard draws every system (the generator's sequence), runs its own */
      double t_out[N_OUT];
      for (int q = 0; q < N_OUT - 1; q++) t_out[q] = pwa_uniform(&rng, 0.05, 0.95) * T_END;
      for (int a = 1; a < N_OUT - 1; a++) /* ascending */
        for (int b = a; b > 0 && t_out[b] < t_out[b - 1]; b--) {
          const double tmp = t_out[b];
          t_out[b] = t_out[b - 1], t_out[b - 1] = tmp;
        }
      t_out[N_OUT - 1] = T_END;
      pwa_sys S;
      double x0[PWA_MAX_NX], u[PWA_MAX_NU];
      pwa_result ref;
      const int d = pr_draw(&rng, &KINDS[c], T_END, 0, 20000, &S, x0, u, &ref);
      FESD_TEST_CHECK(d > 0, "no system of kind %d found", c);
      int fam[RUNS_PER_SYSTEM], stages[RUNS_PER_SYSTEM], rt[RUNS_PER_SYSTEM];
      for (int r = 0; r < RUNS_PER_SYSTEM; r++) {
        const int f = pwa_int(&pick, 0, ref.n_exit > 0 ? 2 : 3);
        fam[r] = f == 2 ? FESD_RK_LOBATTO_IIIC : f == 3 ? FESD_RK_GAUSS_LEGENDRE : FESD_RK_RADAU_IIA;
        stages[r] = f == 0 ? 2 : f == 1 ? 3 : f == 2 ? 3 : 2;
        rt[r] = pwa_int(&pick, 0, 2);
      }
      if (!d || index % n_shards != shard) continue;
      pwa_opts o; /* the reference again, with the output times */
      pwa_opts_default(&o, T_END);
      o.n_out = N_OUT;
      o.t_out = t_out;
      if (pwa_reference(&S, x0, u, &o, &ref)) continue; /* refused with outputs: skip */
      pr_model pm;
      pr_model_init(&pm, &S, 1);
      for (int r = 0; r < RUNS_PER_SYSTEM; r++) {
        fesd_settings set;
        fesd_settings_default(&set);
        set.family = (fesd_rk_family)fam[r];
        set.stages = stages[r];
        fesd_tolerances tol;
        fesd_tolerances_default(&tol);
        tol.rtol = RTOL[rt[r]];
        tol.atol = 1e-3 * tol.rtol;
        fesd_integrator *it;
        int st = fesd_create(&it, &pm.m, &set);
        if (!st) st = fesd_set_tolerances(it, &tol);
        if (!st) st = fesd_set_state(it, 0.0, x0, u);
        double x_out[N_OUT * PWA_MAX_NX];
        fesd_integrate_info info = {0};
        if (!st) st = fesd_integrate_grid(it, u, N_OUT, t_out, x_out, &info);
        fesd_stats stats = {0};
        fesd_get_stats(it, &stats);
        const fesd_event *ev;
        int n_ev = 0, same = 1;
        fesd_event_log(it, &ev, &n_ev);
        same = n_ev == ref.n_ev;
        for (int e = 0; e < n_ev && same; e++)
          same = ev[e].sys == ref.ev[e].sys && (int)ev[e].kind == ref.ev[e].kind &&
                 fabs(ev[e].t - ref.ev[e].t) <= 1e-3 * T_END;
        double ratio = 0; /* worst error / (rtol |x| + atol) over outputs and components */
        for (int q = 0; q < N_OUT; q++)
          for (int k = 0; k < S.nx; k++) {
            const double xr = q < N_OUT - 1 ? ref.x_out[q][k] : ref.x[k];
            ratio = fmax(ratio, fabs(x_out[q * S.nx + k] - xr) / (tol.rtol * fabs(xr) + tol.atol));
          }
        if (verbose) {
          printf("  kind %d system %d %s s=%d rtol %.0e: %s, %d steps (%d rejected, %d failed attempts), %d events "
                 "(reference %d), error / tolerance %.2f\n",
                 c, index, fesd_rk_family_name(set.family), set.stages, tol.rtol, fesd_status_name(st), info.steps,
                 info.rejected, info.failed_attempts, n_ev, ref.n_ev, ratio);
          fflush(stdout);
        }
        const int bad_flags = stats.nonunique_steps + stats.exit_not_pinned_steps + stats.coarse_steps > 0;
        const int right = st == FESD_OK && same && ratio <= ERR_FACTOR;
        tally *ts[2] = {&tk, &all};
        for (int w = 0; w < 2; w++) {
          ts[w]->runs++;
          ts[w]->ok += st == FESD_OK;
          ts[w]->failed += st != FESD_OK;
          ts[w]->right += right;
          ts[w]->flagged += st == FESD_OK && !right && bad_flags;
          ts[w]->wrong += st == FESD_OK && !right && !bad_flags;
          if (st == FESD_OK && same) ts[w]->worst[rt[r]] = fmax(ts[w]->worst[rt[r]], ratio);
          ts[w]->slow += info.steps > MAX_STEPS;
          if (info.steps > ts[w]->max_steps) ts[w]->max_steps = info.steps;
        }
        if (!right && !(st == FESD_OK && bad_flags)) {
          printf("  %s: kind %d system %d, %s s=%d rtol %.0e: %s, %d events (reference %d)%s, error / tolerance "
                 "%.2f, %d steps\n",
                 st == FESD_OK ? "WRONG" : "FAILED", c, index, fesd_rk_family_name(set.family), set.stages, tol.rtol, fesd_status_name(st), n_ev,
                 ref.n_ev, same ? "" : " not the reference's", ratio, info.steps);
          pr_print_system(&S, x0, u);
        }
        fesd_free(&it);
      }
    }
    printf("%-26s: %3d runs, %3d FESD_OK, %3d right, %d flagged, %d failed, %d silently wrong; worst error / "
           "tolerance %.2f / %.2f / %.2f (rtol 1e-4 / 1e-6 / 1e-8); most steps %d\n",
           KINDS[c].name, tk.runs, tk.ok, tk.right, tk.flagged, tk.failed, tk.wrong, tk.worst[0], tk.worst[1],
           tk.worst[2], tk.max_steps);
  }
  printf("total: %d runs, %d FESD_OK, %d right, %d flagged, %d failed with a status, %d silently wrong; worst error "
         "/ tolerance %.2f / %.2f / %.2f\n",
         all.runs, all.ok, all.right, all.flagged, all.failed, all.wrong, all.worst[0], all.worst[1], all.worst[2]);
  FESD_TEST_CHECK(all.wrong == 0, "%d runs returned FESD_OK without a flag and differ from the reference",
                  all.wrong);
  FESD_TEST_CHECK(all.failed == 0, "%d runs failed with a status", all.failed);
  FESD_TEST_CHECK(all.slow == 0, "%d runs took more than %d steps (most: %d)", all.slow, MAX_STEPS, all.max_steps);
  printf("%d failures\n", fails);
  return fails != 0;
}
